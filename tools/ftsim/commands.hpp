// Subcommands of ftsim, each registered by its own translation unit.
#pragma once

#include <CLI/CLI.hpp>

namespace ftstack::tools {

/// ftsim's exit codes (docs/spec/cli.md). A subcommand's callback stores its code; errors are
/// exceptions, caught once in main (one line on stderr, kExitBadInput).
enum ExitCode : int {
  kExitOk = 0,
  kExitNotMet = 1,    ///< design: no design meets the requirement
  kExitBadInput = 2,  ///< bad options or files
};

/// `ftsim pivot …` — the crossed-strip flexure pivot solver (docs/spec/cli.md).
void AddPivotCommand(CLI::App& app, int* exit_code);
/// `ftsim record …` — recordings with known physics and injected effects (docs/spec/cli.md).
void AddRecordCommand(CLI::App& app, int* exit_code);
/// `ftsim design …` — sensor-body design explorer (docs/spec/cli.md, docs/design.md).
void AddDesignCommand(CLI::App& app, int* exit_code);

}  // namespace ftstack::tools
