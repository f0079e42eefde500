#include "tools/ftcal/file_cmds.hpp"

#include <cstdio>

#include "calibration/file/slots.hpp"
#include "calibration/fit/commands.hpp"

namespace ftstack::tools {

void AddFileCommands(CLI::App* app, FileCli* cli) {
  cli->import_ati = app->add_subcommand("import-ati", "convert an ATI DAQ .cal file (gauge volts)");
  cli->import_ati->add_option("file", cli->ati_path, "ATI calibration file, version 1.0 or 1.1")
      ->required();
  cli->import_ati->add_option("--out", cli->out_path, "calibration file to write")->required();

  cli->install = app->add_subcommand(
      "install", "verify a calibration and make it active in a slot directory (A/B, atomic)");
  cli->install->add_option("cal", cli->cal_path, "calibration file")->required();
  cli->install
      ->add_option("--slots", cli->slots_dir, "slot directory (cal_A.json, cal_B.json, active)")
      ->required();
  cli->active = app->add_subcommand("active", "show the active calibration of a slot directory");
  cli->active->add_option("--slots", cli->slots_dir, "slot directory")->required();

  cli->verify = app->add_subcommand("verify", "check a calibration file's integrity");
  cli->verify->add_option("cal", cli->cal_path, "calibration file")->required();

  cli->payload = app->add_subcommand(
      "payload", "identify a payload (mass, centre of mass) and the sensor bias from static poses");
  cli->payload
      ->add_option("--in", cli->in_path,
                   "recording: one static reading per row, gx_mps2 gy_mps2 gz_mps2 (gravity in "
                   "the sensor frame) and Fx…Mz")
      ->required();
  cli->payload->add_option("--out", cli->out_path, "payload file to write (JSON, CRC-32)")
      ->required();
  cli->payload
      ->add_option("--max-condition", cli->max_condition, "refuse a pose set above this condition")
      ->check(CLI::Range(2.0, 1e6));
}

bool FileCommandChosen(const FileCli& cli) {
  return *cli.import_ati || *cli.install || *cli.active || *cli.verify || *cli.payload;
}

FtcalExit RunFileCommand(const FileCli& cli, const std::string& date) {
  if (*cli.payload) {
    std::printf("%s",
                cal::PayloadToFile(cli.in_path, cli.out_path, cli.max_condition, date).c_str());
  } else if (*cli.import_ati) {
    const cal::AtiImport imp = cal::ImportAtiCal(cli.ati_path);
    for (const std::string& w : imp.warnings) {
      std::fprintf(stderr, "ftcal: warning: %s\n", w.c_str());
    }
    cal::SaveCalFile(cli.out_path, imp.file);
    std::printf("%swrote %s (input unit V)\n", cal::AtiImportSummary(cli.ati_path, imp).c_str(),
                cli.out_path.c_str());
  } else if (*cli.install) {
    cal::CalSlots slots(cli.slots_dir);
    const char slot = slots.InstallFromPath(cli.cal_path);
    std::printf("%s: installed into slot %c (now active)\n", cli.cal_path.c_str(), slot);
  } else if (*cli.active) {
    std::string note;
    const std::string line = cal::ActiveSlotLine(cli.slots_dir, &note);
    if (!note.empty()) std::fprintf(stderr, "ftcal: warning: %s\n", note.c_str());
    std::printf("%s", line.c_str());
  } else if (*cli.verify) {
    bool incomplete = false;
    std::printf("%s", cal::VerifyCalFile(cli.cal_path, &incomplete).c_str());
    return incomplete ? kExitIncomplete : kExitOk;
  }
  return kExitOk;
}

}  // namespace ftstack::tools
