// ftsim — simulation command line: pivot solver and recordings with known physics.
#include <CLI/CLI.hpp>

#include "tools/ftsim/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ftsim — force/torque sensor physics simulation"};
  app.require_subcommand(1);
  ftstack::tools::AddPivotCommand(app);
  ftstack::tools::AddRecordCommand(app);
  ftstack::tools::AddDesignCommand(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
