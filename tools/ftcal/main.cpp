// ftcal — calibration CLI: fit, apply, check, import-ati, verify, design, payload (logic in
// calibration/ and sim/).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "calibration/commands.hpp"
#include "calibration/slots.hpp"
#include "tools/common.hpp"
#include "tools/ftcal/fit_design_cmd.hpp"

namespace {

/// ftcal's exit codes (docs/spec: command lines).
enum ExitCode : int {
  kExitOk = 0,           ///< done
  kExitError = 1,        ///< bad input or a refused operation: one line on stderr names it
  kExitIncomplete = 3,   ///< verify: the file is intact but flags an axis invalid
  kExitFlagged = 3,      ///< apply: rows carry status bits (no valid wrench) and no --allow-flagged
  kExitCheckFailed = 4,  ///< check: the calibration reads the tool outside its stated uncertainty
};

}  // namespace

namespace ftstack::tools {

std::string Today() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

/// The unit options fit, apply and check share (recording-format.md, "Declared bridge units").
void AddUnitOptions(CLI::App* sub, ftstack::UnitOverrides* units) {
  sub->add_option("--bridge-unit", units->unit,
                  "unit of the b* columns: mV/V, V or counts (overrides # bridge_unit)");
  sub->add_option("--converter", units->converter,
                  "converter of counts: \"bits=10,coding=unsigned|signed|offset-binary,gain=1,"
                  "ratiometric=yes,reference_ratio=1,reference_v=…,full_scale_mvv=…\"");
  sub->add_option("--excitation-v", units->excitation_v, "bridge excitation, V")
      ->check(CLI::PositiveNumber);
}

}  // namespace ftstack::tools

namespace {

/// ftcal apply: kExitFlagged when rows carry status bits (their wrench is not a valid reading)
/// unless allowed.
ExitCode RunApply(const std::string& cal_path, const std::string& in_path,
                  const std::string& out_path, const ftstack::UnitOverrides& units,
                  bool allow_flagged) {
  const ftstack::cal::ApplyOutcome res =
      ftstack::cal::ApplyToFile(cal_path, in_path, out_path, units);
  std::istringstream log(res.log);
  for (std::string line; std::getline(log, line);)
    std::fprintf(stderr, "ftcal: %s\n", line.c_str());
  const std::size_t flagged = ftstack::tools::ReportStatusBits(res.status, stderr);
  if (flagged > 0 && !allow_flagged) {
    std::fprintf(stderr,
                 "ftcal: %zu of %zu rows carry status bits (their wrench is not a valid "
                 "reading); exit 3 (--allow-flagged to accept)\n",
                 flagged, res.status.size());
    return kExitFlagged;
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace ftstack;
  using namespace ftstack::tools;
  CLI::App app{"ftcal — fit, apply, check, import and verify force/torque calibrations"};
  app.require_subcommand(1);
  std::string cal_path;
  std::string in_path;
  std::string out_path;

  auto* apply = app.add_subcommand("apply", "run the firmware's fixed-point core on a recording");
  apply->add_option("--cal", cal_path, "calibration file")->required();
  apply->add_option("--in", in_path, "recording with b* columns")->required();
  apply->add_option("--out", out_path, "output recording t,Fx,Fy,Fz,Mx,My,Mz")->required();
  bool allow_flagged = false;
  UnitOverrides apply_units;
  apply->add_flag("--allow-flagged", allow_flagged,
                  "exit 0 even when rows carry status bits (they stay marked in `status`)");
  AddUnitOptions(apply, &apply_units);

  cal::CheckRequest cr;
  double mass_kg = 0;
  std::vector<double> com_m;
  auto* check = app.add_subcommand(
      "check", "weigh a known tool in a few robot poses: gain and cross-talk errors, verdict");
  check->add_option("--cal", cr.cal_path, "calibration file")->required();
  check
      ->add_option("--in", cr.in_path,
                   "static poses: gx_mps2 gy_mps2 gz_mps2 (gravity, sensor frame), b*, "
                   "optional pose")
      ->required();
  check->add_option("--payload", cr.payload_path, "the tool's payload file (ftcal payload)");
  auto* mass_opt =
      check->add_option("--mass-kg", mass_kg, "the tool's mass, kg")->check(CLI::PositiveNumber);
  check->add_option("--com-m", com_m, "the tool's centre of mass X,Y,Z, m (sensor frame)")
      ->delimiter(',')
      ->expected(3);
  AddUnitOptions(check, &cr.units);

  std::string ati_path;
  auto* import_ati = app.add_subcommand("import-ati", "convert an ATI DAQ .cal file (gauge volts)");
  import_ati->add_option("file", ati_path, "ATI calibration file, version 1.0 or 1.1")->required();
  import_ati->add_option("--out", out_path, "calibration file to write")->required();

  std::string slots_dir;
  auto* install = app.add_subcommand(
      "install", "verify a calibration and make it active in a slot directory (A/B, atomic)");
  install->add_option("cal", cal_path, "calibration file")->required();
  install->add_option("--slots", slots_dir, "slot directory (cal_A.json, cal_B.json, active)")
      ->required();
  auto* active = app.add_subcommand("active", "show the active calibration of a slot directory");
  active->add_option("--slots", slots_dir, "slot directory")->required();

  auto* verify = app.add_subcommand("verify", "check a calibration file's integrity");
  verify->add_option("cal", cal_path, "calibration file")->required();

  double max_condition = 30.0;
  auto* payload = app.add_subcommand(
      "payload", "identify a payload (mass, centre of mass) and the sensor bias from static poses");
  payload
      ->add_option("--in", in_path,
                   "recording: one static reading per row, gx_mps2 gy_mps2 gz_mps2 (gravity in "
                   "the sensor frame) and Fx…Mz")
      ->required();
  payload->add_option("--out", out_path, "payload file to write (JSON, CRC-32)")->required();
  payload->add_option("--max-condition", max_condition, "refuse a pose set above this condition")
      ->check(CLI::Range(2.0, 1e6));

  FitCli fit_cli;
  CLI::App* fit = AddFitCommand(&app, &fit_cli);
  DesignCli design_cli;
  CLI::App* design = AddDesignCommand(&app, &design_cli);

  CLI11_PARSE(app, argc, argv);
  try {
    if (*fit) {
      RunFitCommand(fit_cli, Today());
    } else if (*check) {
      if (*mass_opt) cr.mass_kg = mass_kg;
      if (com_m.size() == 3) cr.com_m = std::array<double, 3>{com_m[0], com_m[1], com_m[2]};
      std::string text;
      const cal::CheckResult r = cal::RunCheck(cr, &text);
      std::printf("%s", text.c_str());
      return r.pass ? kExitOk : kExitCheckFailed;
    } else if (*payload) {
      std::printf("%s", cal::PayloadToFile(in_path, out_path, max_condition, Today()).c_str());
    } else if (*import_ati) {
      const cal::AtiImport imp = cal::ImportAtiCal(ati_path);
      for (const std::string& w : imp.warnings)
        std::fprintf(stderr, "ftcal: warning: %s\n", w.c_str());
      cal::SaveCalFile(out_path, imp.file);
      std::printf("%swrote %s (input unit V)\n", cal::AtiImportSummary(ati_path, imp).c_str(),
                  out_path.c_str());
    } else if (*install) {
      cal::CalSlots slots(slots_dir);
      const char slot = slots.InstallFromPath(cal_path);
      std::printf("%s: installed into slot %c (now active)\n", cal_path.c_str(), slot);
    } else if (*active) {
      std::string note;
      const std::string line = cal::ActiveSlotLine(slots_dir, &note);
      if (!note.empty()) std::fprintf(stderr, "ftcal: warning: %s\n", note.c_str());
      std::printf("%s", line.c_str());
    } else if (*apply) {
      return RunApply(cal_path, in_path, out_path, apply_units, allow_flagged);
    } else if (*verify) {
      bool incomplete = false;
      std::printf("%s", cal::VerifyCalFile(cal_path, &incomplete).c_str());
      return incomplete ? kExitIncomplete : kExitOk;
    } else if (*design) {
      RunDesignCommand(design_cli);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftcal: %s\n", e.what());
    return kExitError;
  }
  return kExitOk;
}
