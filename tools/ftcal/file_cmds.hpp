// ftcal's calibration-file subcommands: import-ati, install, active, verify and payload.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "tools/ftcal/check_apply_cmd.hpp"

namespace ftstack::tools {

/// What the file subcommands are told, and which of them was chosen.
struct FileCli {
  std::string cal_path;
  std::string in_path;
  std::string out_path;
  std::string ati_path;
  std::string slots_dir;
  double max_condition = 30.0;
  CLI::App* import_ati = nullptr;
  CLI::App* install = nullptr;
  CLI::App* active = nullptr;
  CLI::App* verify = nullptr;
  CLI::App* payload = nullptr;
};
/// Adds import-ati, install, active, verify and payload with their options to `app`.
void AddFileCommands(CLI::App* app, FileCli* cli);
/// Whether one of them was chosen.
[[nodiscard]] bool FileCommandChosen(const FileCli& cli);
/// Runs the chosen one (throws with one line for bad input); kExitIncomplete when verify finds an
/// axis flagged invalid.
[[nodiscard]] FtcalExit RunFileCommand(const FileCli& cli, const std::string& date);

}  // namespace ftstack::tools
