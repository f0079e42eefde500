#include "tools/ftcal/check_apply_cmd.hpp"

#include <array>
#include <cstdio>
#include <sstream>

#include "tools/common.hpp"
#include "tools/ftcal/fit_design_cmd.hpp"

namespace ftstack::tools {

CLI::App* AddCheckCommand(CLI::App* app, CheckCli* cli) {
  auto* check = app->add_subcommand(
      "check", "weigh a known tool in a few robot poses: gain and cross-talk errors, verdict");
  check->add_option("--cal", cli->request.cal_path, "calibration file")->required();
  check
      ->add_option("--in", cli->request.in_path,
                   "static poses: gx_mps2 gy_mps2 gz_mps2 (gravity, sensor frame), b*, "
                   "optional pose")
      ->required();
  check->add_option("--payload", cli->request.payload_path,
                    "the tool's payload file (ftcal payload)");
  cli->mass_option = check->add_option("--mass-kg", cli->mass_kg, "the tool's mass, kg")
                         ->check(CLI::PositiveNumber);
  check->add_option("--com-m", cli->com_m, "the tool's centre of mass X,Y,Z, m (sensor frame)")
      ->delimiter(',')
      ->expected(3);
  check
      ->add_option("--mass-sigma-kg", cli->request.mass_sigma_kg,
                   "standard uncertainty of the tool's mass, kg")
      ->check(CLI::NonNegativeNumber);
  check
      ->add_option("--com-sigma-m", cli->request.com_sigma_m,
                   "standard uncertainty of each centre-of-mass coordinate, m")
      ->check(CLI::NonNegativeNumber);
  check
      ->add_option("--pose-angle-sigma-deg", cli->pose_angle_sigma_deg,
                   "standard uncertainty of each pose's orientation from the robot, deg")
      ->check(CLI::NonNegativeNumber);
  AddUnitOptions(check, &cli->request.units);
  return check;
}

FtcalExit RunCheckCommand(CheckCli cli) {
  if (*cli.mass_option) cli.request.mass_kg = cli.mass_kg;
  if (cli.com_m.size() == 3) {
    cli.request.com_m = std::array<double, 3>{cli.com_m[0], cli.com_m[1], cli.com_m[2]};
  }
  cli.request.pose_angle_sigma_rad = cli.pose_angle_sigma_deg * 3.14159265358979323846 / 180.0;
  std::string text;
  const cal::CheckResult r = cal::RunCheck(cli.request, &text);
  std::printf("%s", text.c_str());
  return r.pass ? kExitOk : kExitCheckFailed;
}

CLI::App* AddApplyCommand(CLI::App* app, ApplyCli* cli) {
  auto* apply = app->add_subcommand("apply", "run the firmware's fixed-point core on a recording");
  apply->add_option("--cal", cli->cal_path, "calibration file")->required();
  apply->add_option("--in", cli->in_path, "recording with b* columns")->required();
  apply->add_option("--out", cli->out_path, "output recording t,Fx,Fy,Fz,Mx,My,Mz")->required();
  apply->add_flag("--allow-flagged", cli->allow_flagged,
                  "exit 0 even when rows carry status bits (they stay marked in `status`)");
  AddUnitOptions(apply, &cli->units);
  return apply;
}

FtcalExit RunApplyCommand(const ApplyCli& cli) {
  const cal::ApplyOutcome res =
      cal::ApplyToFile(cli.cal_path, cli.in_path, cli.out_path, cli.units);
  std::istringstream log(res.log);
  for (std::string line; std::getline(log, line);) {
    std::fprintf(stderr, "ftcal: %s\n", line.c_str());
  }
  const std::size_t flagged = ReportStatusBits(res.status, stderr);
  if (flagged > 0 && !cli.allow_flagged) {
    std::fprintf(stderr,
                 "ftcal: %zu of %zu rows carry status bits (their wrench is not a valid "
                 "reading); exit 3 (--allow-flagged to accept)\n",
                 flagged, res.status.size());
    return kExitFlagged;
  }
  return kExitOk;
}

}  // namespace ftstack::tools
