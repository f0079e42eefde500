// ftcal's fit and design subcommands: the glue between sensor descriptions (sim/) and the
// calibration library, and the helpers every ftcal subcommand shares.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calibration/fit/commands.hpp"
#include "measurement/units.hpp"
#include "tools/unit_options.hpp"

namespace ftstack::tools {

/// Today's date, ISO 8601 (UTC).
[[nodiscard]] std::string Today();

/// What `ftcal fit` is told on the command line.
struct FitCli {
  cal::FitRequest request;
  std::string out_path;
  std::string report_path;
  std::string sensor;  // fit's own: design's default (builtin) is not fit's
  std::string rated;
  bool by_block = false;
};
/// Adds `fit` and its options to `app`.
CLI::App* AddFitCommand(CLI::App* app, FitCli* cli);
/// Resolves --sensor (rated range, converter) and --rated, fits, writes the file and the report,
/// prints the summary. Throws with one line for bad input.
void RunFitCommand(FitCli cli, const std::string& date);

/// What `ftcal design` is told.
struct DesignCli {
  std::string sensor = "builtin";
  std::string profile_out;
  std::string simulate_out;
  double rate_hz = 1000.0;
  std::vector<double> temps;
};
/// Adds `design` and its options to `app`.
CLI::App* AddDesignCommand(CLI::App* app, DesignCli* cli);
/// Prints the load sequence; writes its keyframe profile and a simulated rig run when asked.
void RunDesignCommand(const DesignCli& cli);

}  // namespace ftstack::tools
