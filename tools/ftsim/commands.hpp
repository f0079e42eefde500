// Subcommands of ftsim, each registered by its own translation unit.
#pragma once

#include <CLI/CLI.hpp>

namespace ftstack::tools {

/// `ftsim pivot …` — the crossed-strip flexure pivot solver (docs/spec/cli.md).
void AddPivotCommand(CLI::App& app);
/// `ftsim record …` — recordings with known physics and injected effects (docs/spec/cli.md).
void AddRecordCommand(CLI::App& app);
/// `ftsim design …` — sensor-body design explorer (docs/spec/cli.md, docs/design.md).
void AddDesignCommand(CLI::App& app);

}  // namespace ftstack::tools
