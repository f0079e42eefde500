// ftdiag — sim-vs-real diagnosis (shared spec diagnosis.md). All logic lives in ftstack_tool_diag.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "tools/diag/cli.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ftdiag: locate and explain the mismatch between a simulation and a real recording"};
  app.require_subcommand(1);
  ftstack::diag::AddCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return ftstack::diag::LastExitCode();
}
