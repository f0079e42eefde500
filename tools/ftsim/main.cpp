// ftsim — simulation command line: pivot solver and recordings with known physics.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "tools/ftsim/commands.hpp"

int main(int argc, char** argv) {
  using namespace ftstack::tools;
  CLI::App app{"ftsim — force/torque sensor physics simulation"};
  app.require_subcommand(1);
  int exit_code = kExitOk;
  AddPivotCommand(app, &exit_code);
  AddRecordCommand(app, &exit_code);
  AddDesignCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {  // every subcommand's errors end here: one line
    std::cout.flush();
    const std::vector<CLI::App*> used = app.get_subcommands();
    std::fprintf(stderr, "ftsim %s: %s\n", used.empty() ? "" : used.front()->get_name().c_str(),
                 e.what());
    return kExitBadInput;
  }
  std::cout.flush();
  return exit_code;
}
