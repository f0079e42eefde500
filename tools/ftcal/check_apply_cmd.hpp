// ftcal's check and apply subcommands: their options and the exit codes they end with.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calibration/fit/commands.hpp"
#include "measurement/units.hpp"

namespace ftstack::tools {

/// ftcal's exit codes (docs/spec: command lines).
enum FtcalExit : int {
  kExitOk = 0,           ///< done
  kExitError = 1,        ///< bad input or a refused operation: one line on stderr names it
  kExitIncomplete = 3,   ///< verify: the file is intact but flags an axis invalid
  kExitFlagged = 3,      ///< apply: rows carry status bits (no valid wrench) and no --allow-flagged
  kExitCheckFailed = 4,  ///< check: the calibration reads the tool outside its stated uncertainty
};

/// What `ftcal check` is told.
struct CheckCli {
  cal::CheckRequest request;
  double mass_kg = 0.0;
  std::vector<double> com_m;
  double pose_angle_sigma_deg = 0.0;
  CLI::Option* mass_option = nullptr;
};
/// Adds `check` and its options to `app`.
CLI::App* AddCheckCommand(CLI::App* app, CheckCli* cli);
/// Weighs the tool in the recorded poses, prints the report; kExitCheckFailed on a failed verdict.
[[nodiscard]] FtcalExit RunCheckCommand(CheckCli cli);

/// What `ftcal apply` is told.
struct ApplyCli {
  std::string cal_path;
  std::string in_path;
  std::string out_path;
  UnitOverrides units;
  bool allow_flagged = false;
};
/// Adds `apply` and its options to `app`.
CLI::App* AddApplyCommand(CLI::App* app, ApplyCli* cli);
/// Runs the firmware's core over the recording; kExitFlagged when rows carry status bits (their
/// wrench is not a valid reading) unless allowed.
[[nodiscard]] FtcalExit RunApplyCommand(const ApplyCli& cli);

}  // namespace ftstack::tools
