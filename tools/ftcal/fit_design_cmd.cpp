#include "tools/ftcal/fit_design_cmd.hpp"

#include <cmath>
#include <cstdio>

#include "calibration/fit/fit_report.hpp"
#include "sim/rig.hpp"
#include "sim/sensor_description.hpp"
#include "tools/common.hpp"

namespace ftstack::tools {

CLI::App* AddFitCommand(CLI::App* app, FitCli* cli) {
  cal::FitRequest& fr = cli->request;
  auto* fit = app->add_subcommand("fit", "fit a calibration to rig data (reference wrench + b*)");
  fit->add_option("--in", fr.in_path,
                  "rig recording (t, b0…, Fx…Mz or mass_kg arm_*_m g*_mps2, optional temp_C, "
                  "block/pose, group)")
      ->required();
  fit->add_option("--out", cli->out_path, "calibration file to write")->required();
  fit->add_option("--report", cli->report_path, "self-contained HTML report with plots");
  fit->add_option("--model", fr.model_name,
                  "auto (best held-out), linear, linear-temp, quadratic-diag, quadratic, "
                  "quadratic-temp");
  fit->add_option("--rated", cli->rated,
                  "rated range FX,FY,FZ,MX,MY,MZ (default: --sensor's; one of the two is "
                  "required)");
  fit->add_option("--sensor", cli->sensor,
                  "sensor description (rated range and converter), or builtin; without it the "
                  "file is made for a generic 24-bit converter of +-3.90625 mV/V");
  fit->add_option("--serial", fr.serial, "serial number written to the file");
  fit->add_option("--folds", fr.folds, "cross-validation folds over whole groups (or blocks)")
      ->check(CLI::Range(2, 100));
  fit->add_flag("--validate-by-block", cli->by_block,
                "hold out load blocks (holds) instead of load directions (groups)");
  fit->add_flag("--allow-unexcited", fr.allow_unexcited,
                "write axes the rig did not excite flagged invalid (ftd then never serves them) "
                "instead of refusing");
  fit->add_flag("--identify-jig", fr.identify_jig,
                "known-mass recordings: identify the loading jig's mass and centre of mass and "
                "add its load to the reference");
  AddUnitOptions(fit, &fr.units);
  return fit;
}

void RunFitCommand(FitCli cli, const std::string& date) {
  cal::FitRequest& req = cli.request;
  req.by_group = !cli.by_block;
  req.date = date;
  if (!cli.sensor.empty()) {
    const sim::SensorDescription s = sim::LoadSensorDescription(cli.sensor);
    const Wrench r = s.model->rated();
    req.rated = std::array<double, 6>{r(0), r(1), r(2), r(3), r(4), r(5)};
    hal::AdcInfo adc{};
    adc.channel_count = static_cast<std::uint8_t>(s.model->channel_count());
    const std::int64_t half = std::int64_t{1} << (s.adc.resolution_bits - 1);
    adc.max_counts = static_cast<std::int32_t>(half - 1);
    adc.min_counts = static_cast<std::int32_t>(-half);
    adc.full_scale_nvv = std::llround(1000.0 * s.adc.reference_ratio / s.adc_gain * 1e6);
    req.adc = adc;
  }
  if (!cli.rated.empty()) req.rated = ParseWrench(cli.rated);
  const cal::FitOutcome fit = cal::FitFromRecording(req);
  cal::SaveCalFile(cli.out_path, fit.file);
  std::printf("%s", fit.text.c_str());
  if (!cli.report_path.empty()) {
    cal::WriteFitReport(cli.report_path, fit.result, fit.data, fit.fixed, req.in_path);
    std::printf("report: %s\n", cli.report_path.c_str());
  }
  std::printf("wrote %s\n", cli.out_path.c_str());
}

CLI::App* AddDesignCommand(CLI::App* app, DesignCli* cli) {
  auto* design = app->add_subcommand("design", "propose a calibration rig load sequence");
  design->add_option("--sensor", cli->sensor, "sensor description or builtin");
  design->add_option("--out", cli->profile_out, "keyframe profile CSV (t, Fx…Mz, temp_C)");
  design->add_option("--simulate", cli->simulate_out, "also simulate the rig into this recording");
  design->add_option("--rate-hz", cli->rate_hz, "sample rate of the simulation")
      ->check(CLI::Range(1.0, 100000.0));
  design->add_option("--temperatures", cli->temps, "repeat at these body temperatures, °C")
      ->delimiter(',');
  return design;
}

void RunDesignCommand(const DesignCli& cli) {
  const sim::SensorDescription s = sim::LoadSensorDescription(cli.sensor);
  sim::RigDesignOptions ro;
  ro.temperatures_c = cli.temps;
  const auto steps = sim::DesignRig(s.model->rated(), ro);
  const auto keys = sim::RigKeys(steps, ro);
  std::printf("%s%zu loads, %.1f s; condition number of the load set: %.3g\n",
              sim::RigStepTable(steps).c_str(), steps.size(), keys.back().t_s,
              cal::LoadSetCondition(sim::RigLoads(steps), s.model->rated()));
  if (!cli.profile_out.empty()) {
    WriteRecording(cli.profile_out, sim::RigProfileRecording(keys));
    std::printf("wrote %s\n", cli.profile_out.c_str());
  }
  if (!cli.simulate_out.empty()) {
    WriteRecording(cli.simulate_out, sim::SimulateRig(s, keys, cli.rate_hz, 1));
    std::printf("wrote %s\n", cli.simulate_out.c_str());
  }
}

}  // namespace ftstack::tools
