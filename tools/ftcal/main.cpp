// ftcal — calibration command line: fit, apply, import-ati, verify, design (logic in calibration/).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "calibration/apply.hpp"
#include "calibration/ati.hpp"
#include "calibration/cal_file.hpp"
#include "calibration/fit.hpp"
#include "calibration/fit_report.hpp"
#include "calibration/input_units.hpp"
#include "calibration/slots.hpp"
#include "measurement/recording.hpp"
#include "sim/rig.hpp"
#include "sim/sensor_description.hpp"
#include "tools/common.hpp"

namespace {

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

}  // namespace

int main(int argc, char** argv) {
  using namespace ftstack;
  CLI::App app{"ftcal — fit, apply, import and verify force/torque calibrations"};
  app.require_subcommand(1);
  std::string cal_path;
  std::string in_path;
  std::string out_path;
  std::string report_path;
  std::string model_name = "auto";
  std::string rated_text;
  std::string sensor_path;
  std::string serial = "unknown";
  int folds = 10;
  UnitOverrides units;
  bool allow_flagged = false;
  auto unit_options = [&units](CLI::App* sub) {
    sub->add_option("--bridge-unit", units.unit,
                    "unit of the b* columns: mV/V, V or counts (overrides # bridge_unit)");
    sub->add_option("--converter", units.converter,
                    "converter of counts: \"bits=10,coding=unsigned|signed|offset-binary,gain=1,"
                    "ratiometric=yes,reference_ratio=1,reference_v=…,full_scale_mvv=…\"");
    sub->add_option("--excitation-v", units.excitation_v, "bridge excitation, V")
        ->check(CLI::PositiveNumber);
  };

  auto* fit = app.add_subcommand("fit", "fit a calibration to rig data (reference wrench + b*)");
  fit->add_option("--in", in_path, "rig recording (t, Fx…Mz, b0…, optional temp_C, block/pose)")
      ->required();
  fit->add_option("--out", out_path, "calibration file to write")->required();
  fit->add_option("--report", report_path, "self-contained HTML report with plots");
  fit->add_option("--model", model_name,
                  "auto (best held-out), linear, linear-temp, quadratic, quadratic-temp");
  fit->add_option("--rated", rated_text,
                  "rated range FX,FY,FZ,MX,MY,MZ (default: --sensor's, "
                  "else the largest load in the data)");
  fit->add_option("--sensor", sensor_path, "sensor description (rated range and ADC), or builtin");
  fit->add_option("--serial", serial, "serial number written to the file");
  fit->add_option("--folds", folds, "cross-validation folds over whole load blocks")
      ->check(CLI::Range(2, 100));
  unit_options(fit);

  auto* apply = app.add_subcommand("apply", "run the firmware's fixed-point core on a recording");
  apply->add_option("--cal", cal_path, "calibration file")->required();
  apply->add_option("--in", in_path, "recording with b* columns")->required();
  apply->add_option("--out", out_path, "output recording t,Fx,Fy,Fz,Mx,My,Mz")->required();
  apply->add_flag("--allow-flagged", allow_flagged,
                  "exit 0 even when rows carry status bits (they stay marked in `status`)");
  unit_options(apply);

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

  std::string profile_out;
  std::string simulate_out;
  double rate_hz = 1000.0;
  std::vector<double> temps;
  auto* design = app.add_subcommand("design", "propose a calibration rig load sequence");
  design->add_option("--sensor", sensor_path, "sensor description or builtin")
      ->default_val("builtin");
  design->add_option("--out", profile_out, "keyframe profile CSV (t, Fx…Mz, temp_C)");
  design->add_option("--simulate", simulate_out, "also simulate the rig into this recording");
  design->add_option("--rate-hz", rate_hz, "sample rate of the simulation")
      ->check(CLI::Range(1.0, 100000.0));
  design->add_option("--temperatures", temps, "repeat at these body temperatures, °C")
      ->delimiter(',');

  CLI11_PARSE(app, argc, argv);
  try {
    if (*fit) {
      ReadOptions opt;
      opt.require_bridges = true;
      opt.require_wrench = true;
      Recording rec = ReadRecording(in_path, opt);
      cal::FitOptions fo;
      fo.folds = folds;
      hal::AdcInfo adc{};
      bool have_adc = false;
      if (!sensor_path.empty()) {
        const sim::SensorDescription s = sim::LoadSensorDescription(sensor_path);
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
      const cal::FitInput input = cal::PrepareFitInput(&rec, units, adc);
      adc = input.adc;
      std::printf("%s\n", input.description.c_str());
      if (!rated_text.empty()) fo.rated = tools::ParseWrench(rated_text);
      if (model_name != "auto") {
        const auto k = cal::ParseModelKind(model_name);
        if (!k) throw std::invalid_argument("unknown --model '" + model_name + "'");
        fo.models = {*k};
      }
      cal::BlockOptions bo;
      bo.scale = fo.rated;
      const cal::RigData data = cal::RigDataFromRecording(rec, bo);
      const cal::FitResult result = cal::FitCalibration(data, fo);
      cal::CalFile file = cal::CalFileFromFit(result, adc, serial, Today());
      cal::RecordInputUnit(input, &file);
      fw::LoadReport rep{};
      (void)cal::ToFixed(file, file.adc, &rep);
      cal::SaveCalFile(out_path, file);
      std::printf("%s", cal::FitSummary(result, rep).c_str());
      if (!report_path.empty()) {
        cal::WriteFitReport(report_path, result, data, rep, in_path);
        std::printf("report: %s\n", report_path.c_str());
      }
      std::printf("wrote %s\n", out_path.c_str());
    } else if (*import_ati) {
      const cal::AtiImport imp = cal::ImportAtiCal(ati_path);
      for (const std::string& w : imp.warnings)
        std::fprintf(stderr, "ftcal: warning: %s\n", w.c_str());
      cal::SaveCalFile(out_path, imp.file);
      std::printf("%s: ATI calibration version %s, serial %s, %d gauges, matrix from %s\n",
                  ati_path.c_str(), imp.version.c_str(), imp.file.serial.c_str(),
                  imp.file.cal.channel_count,
                  imp.used_user_axis ? "UserAxis rows" : "Axis rows / scale + BasicTransform");
      static const char* const kAxisNames[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
      for (std::size_t a = 0; a < 6; ++a) {
        std::printf("  %s (%s/V):", kAxisNames[a], a < 3 ? "N" : "N*m");
        for (std::size_t c = 0; c < imp.file.cal.channel_count; ++c) {
          std::printf(" %10.5f", imp.file.cal.matrix[a][c]);
        }
        std::printf("   rated %g\n", imp.file.rated[a]);
      }
      fw::LoadReport rep{};
      (void)cal::ToFixed(imp.file, imp.file.adc, &rep);
      PrintWorstCase(rep);
      std::printf("wrote %s (input unit V)\n", out_path.c_str());
    } else if (*install) {
      cal::CalSlots slots(slots_dir);
      const char slot = slots.InstallFromPath(cal_path);
      std::printf("%s: installed into slot %c (now active)\n", cal_path.c_str(), slot);
    } else if (*active) {
      cal::CalSlots slots(slots_dir);
      char slot = 0;
      std::string note;
      const cal::CalFile f = slots.LoadActive(&slot, &note);
      if (!note.empty()) std::fprintf(stderr, "ftcal: warning: %s\n", note.c_str());
      std::printf("slot %c: serial %s, date %s, source %s\n", slot, f.serial.c_str(),
                  f.date.c_str(), f.source.c_str());
    } else if (*apply) {
      const cal::CalFile cal = cal::LoadCalFile(cal_path);
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
        return 3;
      }
    } else if (*verify) {
      const cal::CalFile cal = cal::LoadCalFile(cal_path);
      fw::LoadReport rep{};
      (void)cal::ToFixed(cal, cal.adc, &rep);
      std::printf(
          "%s: OK (schema %s, %d channels, %d second-order terms, temperature %s, "
          "serial %s, CRC valid, fixed-point form matches)\n",
          cal_path.c_str(), cal::kCalSchema, cal.cal.channel_count, cal.cal.product_count,
          cal.cal.temperature_compensated ? "compensated" : "not compensated", cal.serial.c_str());
      PrintWorstCase(rep);
    } else if (*design) {
      const sim::SensorDescription s = sim::LoadSensorDescription(sensor_path);
      sim::RigDesignOptions ro;
      ro.temperatures_c = temps;
      const auto steps = sim::DesignRig(s.model->rated(), ro);
      const auto keys = sim::RigKeys(steps, ro);
      for (std::size_t i = 0; i < steps.size(); ++i) {
        std::printf("%4zu  %-28s  %8.2f %8.2f %8.2f %7.3f %7.3f %7.3f  %5.1f C\n", i,
                    steps[i].label.c_str(), steps[i].wrench(0), steps[i].wrench(1),
                    steps[i].wrench(2), steps[i].wrench(3), steps[i].wrench(4), steps[i].wrench(5),
                    steps[i].temperature_c);
      }
      std::printf("%zu loads, %.1f s; condition number of the load set: %.3g\n", steps.size(),
                  keys.back().t_s, cal::LoadSetCondition(sim::RigLoads(steps), s.model->rated()));
      if (!profile_out.empty()) {
        Recording prof;
        prof.names = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "temp_C"};
        prof.columns.resize(8);
        for (const auto& k : keys) {
          prof.columns[0].push_back(k.t_s);
          for (int a = 0; a < 6; ++a)
            prof.columns[static_cast<std::size_t>(1 + a)].push_back(k.w(a));
          prof.columns[7].push_back(k.temperature_c);
        }
        prof.metadata.push_back("source: ftcal design");
        WriteRecording(profile_out, prof);
        std::printf("wrote %s\n", profile_out.c_str());
      }
      if (!simulate_out.empty()) {
        WriteRecording(simulate_out, sim::SimulateRig(s, keys, rate_hz, 1));
        std::printf("wrote %s\n", simulate_out.c_str());
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftcal: %s\n", e.what());
    return 1;
  }
  return 0;
}
