// ftcal — calibration CLI: fit, apply, import-ati, verify, design, payload (logic in calibration/).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "calibration/apply.hpp"
#include "calibration/ati.hpp"
#include "calibration/cal_file.hpp"
#include "calibration/excitation.hpp"
#include "calibration/fit.hpp"
#include "calibration/fit_report.hpp"
#include "calibration/input_units.hpp"
#include "calibration/known_mass.hpp"
#include "calibration/payload.hpp"
#include "calibration/slots.hpp"
#include "measurement/recording.hpp"
#include "sim/rig.hpp"
#include "sim/sensor_description.hpp"
#include "tools/common.hpp"

namespace {

/// ftcal's exit codes (docs/spec: command lines).
enum ExitCode : int {
  kExitOk = 0,          ///< done
  kExitError = 1,       ///< bad input or a refused operation: one line on stderr names it
  kExitIncomplete = 3,  ///< verify: the file is intact but flags an axis invalid
  kExitFlagged = 3,     ///< apply: rows carry status bits (no valid wrench) and no --allow-flagged
};

std::string Today() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

void PrintWorstCase(const ftstack::fw::LoadReport& rep) {
  std::printf(
      "worst-case fixed-point error: Fx %.3g N, Fy %.3g N, Fz %.3g N, Mx %.3g N·m, "
      "My %.3g N·m, Mz %.3g N·m\n",
      rep.worst_case_error_si[0], rep.worst_case_error_si[1], rep.worst_case_error_si[2],
      rep.worst_case_error_si[3], rep.worst_case_error_si[4], rep.worst_case_error_si[5]);
}

/// A rig recording for `ftcal fit`: with a reference wrench, or with known masses (mass_kg,
/// arm_*_m, g*_mps2) turned into one, plus the jig's load when asked to identify it.
ftstack::Recording ReadRigRecording(const std::string& path, bool identify_jig) {
  using namespace ftstack;
  ReadOptions opt;
  opt.require_bridges = true;
  Recording rec = ReadRecording(path, opt);
  if (!cal::IsKnownMassRecording(rec)) {
    if (identify_jig) throw std::invalid_argument("--identify-jig needs a mass_kg column");
    for (const std::string& c : WrenchColumns()) (void)rec.Column(c);  // names the file
    return rec;
  }
  rec = cal::WithReferenceFromMasses(rec);
  if (identify_jig) {
    const cal::JigEstimate jig = cal::IdentifyJig(rec);
    std::printf("jig: %.4f ± %.4f kg, centre of mass %.2f %.2f %.2f mm (± %.2f, %.2f, %.2f mm)\n",
                jig.mass_kg, jig.mass_sigma_kg, jig.com_m[0] * 1e3, jig.com_m[1] * 1e3,
                jig.com_m[2] * 1e3, jig.com_sigma_m[0] * 1e3, jig.com_sigma_m[1] * 1e3,
                jig.com_sigma_m[2] * 1e3);
    rec = cal::WithJig(rec, jig);
  }
  return rec;
}

/// ftcal payload: identify, write the payload file, print the summary.
void RunPayload(const std::string& in_path, const std::string& out_path, double max_condition) {
  using namespace ftstack;
  const Recording rec = ReadRecording(in_path);
  cal::PayloadFitOptions po;
  po.max_condition = max_condition;
  cal::PayloadFit pfit = cal::FitPayload(cal::PayloadReadingsFromRecording(rec), po);
  pfit.file.date = Today();
  cal::SavePayloadFile(out_path, pfit.file);
  std::printf("%swrote %s\n", cal::PayloadSummary(pfit).c_str(), out_path.c_str());
}

}  // namespace

/// What `ftcal fit` is told.
struct FitArgs {
  std::string in_path;
  std::string out_path;
  std::string report_path;
  std::string model_name = "auto";
  std::string rated_text;
  std::string fit_sensor;  // fit's own: design's default (builtin) is not fit's
  std::string serial = "unknown";
  int folds = 10;
  bool allow_unexcited = false;
  bool identify_jig = false;     ///< known-mass recordings: identify the loading jig
  ftstack::UnitOverrides units;  ///< --bridge-unit, --converter, --excitation-v
};

/// The unit options fit and apply share (recording-format.md, "Declared bridge units").
void AddUnitOptions(CLI::App* sub, ftstack::UnitOverrides* units) {
  sub->add_option("--bridge-unit", units->unit,
                  "unit of the b* columns: mV/V, V or counts (overrides # bridge_unit)");
  sub->add_option("--converter", units->converter,
                  "converter of counts: \"bits=10,coding=unsigned|signed|offset-binary,gain=1,"
                  "ratiometric=yes,reference_ratio=1,reference_v=…,full_scale_mvv=…\"");
  sub->add_option("--excitation-v", units->excitation_v, "bridge excitation, V")
      ->check(CLI::PositiveNumber);
}

/// `ftcal fit`: reads the rig recording, checks every axis's excitation, fits, writes. Throws.
void RunFit(const FitArgs& args) {
  using namespace ftstack;
  Recording rec = ReadRigRecording(args.in_path, args.identify_jig);
  cal::FitOptions fo;
  fo.folds = args.folds;
  hal::AdcInfo adc{};
  bool have_adc = false;
  if (args.fit_sensor.empty() && args.rated_text.empty()) {
    throw std::invalid_argument(
        "fit needs the rated range: give --sensor FILE|builtin or --rated FX,FY,FZ,MX,MY,MZ");
  }
  if (!args.fit_sensor.empty()) {
    const sim::SensorDescription s = sim::LoadSensorDescription(args.fit_sensor);
    const Wrench r = s.model->rated();
    for (int a = 0; a < 6; ++a) fo.rated[static_cast<std::size_t>(a)] = r(a);
    adc.channel_count = static_cast<std::uint8_t>(s.model->channel_count());
    const std::int64_t half = std::int64_t{1} << (s.adc.resolution_bits - 1);
    adc.max_counts = static_cast<std::int32_t>(half - 1);
    adc.min_counts = static_cast<std::int32_t>(-half);
    adc.full_scale_nvv = std::llround(1000.0 * s.adc.reference_ratio / s.adc_gain * 1e6);
    have_adc = true;
  }
  if (!have_adc) adc = cal::DefaultAdc(static_cast<std::uint8_t>(rec.BridgeCount()));
  // Declared units: the fit is made for the declared converter, else for the assumed one; values
  // outside its range are refused (file:line:column), the b* columns converted in place.
  const cal::FitInput input = cal::PrepareFitInput(&rec, args.units, adc);
  adc = input.adc;
  if (!args.rated_text.empty()) fo.rated = tools::ParseWrench(args.rated_text);
  if (args.model_name != "auto") {
    const auto k = cal::ParseModelKind(args.model_name);
    if (!k) throw std::invalid_argument("unknown --model '" + args.model_name + "'");
    fo.models = {*k};
  }
  cal::BlockOptions bo;
  bo.scale = fo.rated;
  const cal::RigData data = cal::RigDataFromRecording(rec, bo);
  // Every axis must be excited (range against rated, independent of the others), or be
  // written flagged invalid when the user asks: never a row the data could not determine.
  const cal::ExcitationOptions eo;
  const cal::ExcitationReport ex = cal::CheckExcitation(data.wrench, fo.rated, eo);
  if (ex.unexcited != 0 && !args.allow_unexcited) {
    throw std::invalid_argument(args.in_path + ": " + ex.Refusal(fo.rated, eo) +
                                ": refused (--allow-unexcited writes it flagged invalid)");
  }
  const cal::FitResult result = cal::FitCalibration(data, fo);
  // Said once the recording is accepted (a refusal stays one line).
  std::printf("%s\n", input.description.c_str());
  if (!have_adc && !input.declared.has_converter) {
    std::printf("converter: generic 24-bit, +-3.90625 mV/V (no --sensor)\n");
  }
  cal::CalFile file = cal::CalFileFromFit(result, adc, args.serial, Today());
  cal::RecordInputUnit(input, &file);
  file.cal.invalid_axes = ex.unexcited;
  fw::LoadReport rep{};
  (void)cal::ToFixed(file, file.adc, &rep);
  cal::SaveCalFile(args.out_path, file);
  std::printf("%s", cal::FitSummary(result, rep).c_str());
  if (ex.unexcited != 0) {
    std::printf(
        "warning: %s: flagged invalid in %s — ftd serves no value for %s (NaN / 0, "
        "status bit 10)\n",
        ex.Refusal(fo.rated, eo).c_str(), args.out_path.c_str(),
        cal::AxisList(ex.unexcited).c_str());
  }
  if (!args.report_path.empty()) {
    cal::WriteFitReport(args.report_path, result, data, rep, args.in_path);
    std::printf("report: %s\n", args.report_path.c_str());
  }
  std::printf("wrote %s\n", args.out_path.c_str());
}

/// ftcal import-ati: converts, prints the matrix and the fixed-point error, writes.
void RunImportAti(const std::string& ati_path, const std::string& out_path) {
  using namespace ftstack;
  const cal::AtiImport imp = cal::ImportAtiCal(ati_path);
  for (const std::string& w : imp.warnings) std::fprintf(stderr, "ftcal: warning: %s\n", w.c_str());
  cal::SaveCalFile(out_path, imp.file);
  std::printf("%s: ATI calibration version %s, serial %s, %d gauges, matrix from %s\n",
              ati_path.c_str(), imp.version.c_str(), imp.file.serial.c_str(),
              imp.file.cal.channel_count,
              imp.used_user_axis ? "UserAxis rows" : "Axis rows / scale + BasicTransform");
  for (std::size_t a = 0; a < 6; ++a) {
    std::printf("  %s (%s/V):", cal::kAxisNames[a], a < 3 ? "N" : "N*m");
    for (std::size_t c = 0; c < imp.file.cal.channel_count; ++c) {
      std::printf(" %10.5f", imp.file.cal.matrix[a][c]);
    }
    std::printf("   rated %g\n", imp.file.rated[a]);
  }
  fw::LoadReport rep{};
  (void)cal::ToFixed(imp.file, imp.file.adc, &rep);
  PrintWorstCase(rep);
  std::printf("wrote %s (input unit V)\n", out_path.c_str());
}

/// ftcal active: prints the active slot's calibration.
void RunActive(const std::string& slots_dir) {
  using namespace ftstack;
  cal::CalSlots slots(slots_dir);
  char slot = 0;
  std::string note;
  const cal::CalFile f = slots.LoadActive(&slot, &note);
  if (!note.empty()) std::fprintf(stderr, "ftcal: warning: %s\n", note.c_str());
  std::printf("slot %c: serial %s, date %s, source %s\n", slot, f.serial.c_str(), f.date.c_str(),
              f.source.c_str());
}

/// ftcal apply: the firmware's fixed-point core over a recording, in the calibration's input unit;
/// kExitFlagged when rows carry status bits (their wrench is not a valid reading) unless allowed.
ExitCode RunApply(const std::string& cal_path, const std::string& in_path,
                  const std::string& out_path, const ftstack::UnitOverrides& units,
                  bool allow_flagged) {
  using namespace ftstack;
  const cal::CalFile cal = cal::LoadCalFile(cal_path);
  if (cal.cal.invalid_axes != 0) {
    std::fprintf(stderr,
                 "ftcal: warning: %s flags axis %s invalid (not calibrated): its column holds "
                 "0, not a measurement\n",
                 cal_path.c_str(), cal::AxisList(cal.cal.invalid_axes).c_str());
  }
  ReadOptions opt;
  opt.require_bridges = true;
  Recording in = ReadRecording(in_path, opt);
  const std::string used = cal::PrepareApplyInput(&in, units, cal);
  std::fprintf(stderr, "ftcal: %s\n", used.c_str());
  const Recording out = cal::ApplyCalibration(cal, in);
  WriteRecording(out_path, out);
  std::fprintf(stderr, "ftcal: wrote %zu rows to %s\n", in.rows(), out_path.c_str());
  const std::size_t flagged = tools::ReportStatusBits(out.Column("status"), stderr);
  if (flagged > 0 && !allow_flagged) {
    std::fprintf(stderr,
                 "ftcal: %zu of %zu rows carry status bits (their wrench is not a valid "
                 "reading); exit 3 (--allow-flagged to accept)\n",
                 flagged, out.rows());
    return kExitFlagged;
  }
  return kExitOk;
}

/// ftcal verify: integrity and the fixed-point form; kExitIncomplete for a file with invalid axes.
ExitCode RunVerify(const std::string& cal_path) {
  using namespace ftstack;
  const cal::CalFile cal = cal::LoadCalFile(cal_path);
  fw::LoadReport rep{};
  (void)cal::ToFixed(cal, cal.adc, &rep);
  if (cal.cal.invalid_axes != 0) {
    // Intact, but not a calibration of every axis: never "OK" alone (exit 3).
    std::printf(
        "%s: INCOMPLETE: axis %s flagged invalid (not excited on the rig): ftd serves "
        "no value for it (NaN / 0, status bit 10); the file itself is intact (CRC "
        "valid)\n",
        cal_path.c_str(), cal::AxisList(cal.cal.invalid_axes).c_str());
    PrintWorstCase(rep);
    return kExitIncomplete;
  }
  std::printf(
      "%s: OK (schema %s, %d channels, %d second-order terms, temperature %s, "
      "serial %s, CRC valid, fixed-point form matches)\n",
      cal_path.c_str(), cal::kCalSchema, cal.cal.channel_count, cal.cal.product_count,
      cal.cal.temperature_compensated ? "compensated" : "not compensated", cal.serial.c_str());
  PrintWorstCase(rep);
  return kExitOk;
}

/// What `ftcal design` is told.
struct DesignArgs {
  std::string sensor = "builtin";
  std::string profile_out;
  std::string simulate_out;
  double rate_hz = 1000.0;
  std::vector<double> temps;
};

/// ftcal design: the load sequence, optionally its keyframe profile and a simulated rig run.
void RunDesign(const DesignArgs& args) {
  using namespace ftstack;
  const sim::SensorDescription s = sim::LoadSensorDescription(args.sensor);
  sim::RigDesignOptions ro;
  ro.temperatures_c = args.temps;
  const auto steps = sim::DesignRig(s.model->rated(), ro);
  const auto keys = sim::RigKeys(steps, ro);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    std::printf("%4zu  %-28s  %8.2f %8.2f %8.2f %7.3f %7.3f %7.3f  %5.1f C\n", i,
                steps[i].label.c_str(), steps[i].wrench(0), steps[i].wrench(1), steps[i].wrench(2),
                steps[i].wrench(3), steps[i].wrench(4), steps[i].wrench(5), steps[i].temperature_c);
  }
  std::printf("%zu loads, %.1f s; condition number of the load set: %.3g\n", steps.size(),
              keys.back().t_s, cal::LoadSetCondition(sim::RigLoads(steps), s.model->rated()));
  if (!args.profile_out.empty()) {
    Recording prof;
    prof.names = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "temp_C"};
    prof.columns.resize(8);
    for (const auto& k : keys) {
      prof.columns[0].push_back(k.t_s);
      for (int a = 0; a < 6; ++a) prof.columns[static_cast<std::size_t>(1 + a)].push_back(k.w(a));
      prof.columns[7].push_back(k.temperature_c);
    }
    prof.metadata.push_back("source: ftcal design");
    WriteRecording(args.profile_out, prof);
    std::printf("wrote %s\n", args.profile_out.c_str());
  }
  if (!args.simulate_out.empty()) {
    WriteRecording(args.simulate_out, sim::SimulateRig(s, keys, args.rate_hz, 1));
    std::printf("wrote %s\n", args.simulate_out.c_str());
  }
}

int main(int argc, char** argv) {
  using namespace ftstack;
  CLI::App app{"ftcal — fit, apply, import and verify force/torque calibrations"};
  app.require_subcommand(1);
  std::string cal_path;
  std::string in_path;
  std::string out_path;
  FitArgs fa;  // fit's options are its own (design's --sensor default must not reach it)

  auto* fit = app.add_subcommand("fit", "fit a calibration to rig data (reference wrench + b*)");
  fit->add_option("--in", fa.in_path,
                  "rig recording (t, b0…, Fx…Mz or mass_kg arm_*_m g*_mps2, optional temp_C, "
                  "block/pose)")
      ->required();
  fit->add_option("--out", fa.out_path, "calibration file to write")->required();
  fit->add_option("--report", fa.report_path, "self-contained HTML report with plots");
  fit->add_option("--model", fa.model_name,
                  "auto (best held-out), linear, linear-temp, quadratic, quadratic-temp");
  fit->add_option("--rated", fa.rated_text,
                  "rated range FX,FY,FZ,MX,MY,MZ (default: --sensor's; one of the two is "
                  "required)");
  fit->add_option("--sensor", fa.fit_sensor,
                  "sensor description (rated range and converter), or builtin; without it the "
                  "file is made for a generic 24-bit converter of +-3.90625 mV/V");
  fit->add_option("--serial", fa.serial, "serial number written to the file");
  fit->add_option("--folds", fa.folds, "cross-validation folds over whole load blocks")
      ->check(CLI::Range(2, 100));
  fit->add_flag("--allow-unexcited", fa.allow_unexcited,
                "write axes the rig did not excite flagged invalid (ftd then never serves them) "
                "instead of refusing");
  fit->add_flag("--identify-jig", fa.identify_jig,
                "known-mass recordings: identify the loading jig's mass and centre of mass and "
                "add its load to the reference");
  AddUnitOptions(fit, &fa.units);

  auto* apply = app.add_subcommand("apply", "run the firmware's fixed-point core on a recording");
  apply->add_option("--cal", cal_path, "calibration file")->required();
  apply->add_option("--in", in_path, "recording with b* columns")->required();
  apply->add_option("--out", out_path, "output recording t,Fx,Fy,Fz,Mx,My,Mz")->required();
  bool allow_flagged = false;
  UnitOverrides apply_units;
  apply->add_flag("--allow-flagged", allow_flagged,
                  "exit 0 even when rows carry status bits (they stay marked in `status`)");
  AddUnitOptions(apply, &apply_units);

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

  DesignArgs da;
  auto* design = app.add_subcommand("design", "propose a calibration rig load sequence");
  design->add_option("--sensor", da.sensor, "sensor description or builtin")
      ->default_val("builtin");
  design->add_option("--out", da.profile_out, "keyframe profile CSV (t, Fx…Mz, temp_C)");
  design->add_option("--simulate", da.simulate_out, "also simulate the rig into this recording");
  design->add_option("--rate-hz", da.rate_hz, "sample rate of the simulation")
      ->check(CLI::Range(1.0, 100000.0));
  design->add_option("--temperatures", da.temps, "repeat at these body temperatures, °C")
      ->delimiter(',');

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

  CLI11_PARSE(app, argc, argv);
  try {
    if (*fit) {
      RunFit(fa);
    } else if (*payload) {
      RunPayload(in_path, out_path, max_condition);
    } else if (*import_ati) {
      RunImportAti(ati_path, out_path);
    } else if (*install) {
      cal::CalSlots slots(slots_dir);
      const char slot = slots.InstallFromPath(cal_path);
      std::printf("%s: installed into slot %c (now active)\n", cal_path.c_str(), slot);
    } else if (*active) {
      RunActive(slots_dir);
    } else if (*apply) {
      return RunApply(cal_path, in_path, out_path, apply_units, allow_flagged);
    } else if (*verify) {
      return RunVerify(cal_path);
    } else if (*design) {
      RunDesign(da);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftcal: %s\n", e.what());
    return kExitError;
  }
  return kExitOk;
}
