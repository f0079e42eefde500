// ftcal — calibration CLI: fit, apply, check, import-ati, verify, design, payload (logic in
// calibration/ and sim/).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>

#include "tools/ftcal/check_apply_cmd.hpp"
#include "tools/ftcal/file_cmds.hpp"
#include "tools/ftcal/fit_design_cmd.hpp"

namespace ftstack::tools {

std::string Today() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

}  // namespace ftstack::tools

int main(int argc, char** argv) {
  using namespace ftstack;
  using namespace ftstack::tools;
  CLI::App app{"ftcal — fit, apply, check, import and verify force/torque calibrations"};
  app.require_subcommand(1);
  ApplyCli apply_cli;
  CLI::App* apply = AddApplyCommand(&app, &apply_cli);
  CheckCli check_cli;
  CLI::App* check = AddCheckCommand(&app, &check_cli);
  FileCli file_cli;
  AddFileCommands(&app, &file_cli);
  FitCli fit_cli;
  CLI::App* fit = AddFitCommand(&app, &fit_cli);
  DesignCli design_cli;
  CLI::App* design = AddDesignCommand(&app, &design_cli);

  CLI11_PARSE(app, argc, argv);
  try {
    if (*fit) {
      RunFitCommand(fit_cli, Today());
    } else if (*check) {
      return RunCheckCommand(check_cli);
    } else if (FileCommandChosen(file_cli)) {
      return RunFileCommand(file_cli, Today());
    } else if (*apply) {
      return RunApplyCommand(apply_cli);
    } else if (*design) {
      RunDesignCommand(design_cli);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftcal: %s\n", e.what());
    return kExitError;
  }
  return kExitOk;
}
