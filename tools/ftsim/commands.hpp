// Subcommands of ftsim, each registered by its own translation unit.
#pragma once

#include <CLI/CLI.hpp>

namespace ftstack::tools {

/// `ftsim pivot …` — the crossed-strip flexure pivot solver (see shared spec cli.md).
void AddPivotCommand(CLI::App& app);
/// `ftsim record …` — recordings with known physics and injected effects (see cli.md).
void AddRecordCommand(CLI::App& app);

}  // namespace ftstack::tools
