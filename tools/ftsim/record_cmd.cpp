// `ftsim record` — simulated recordings with known physics and injected effects (docs/spec/cli.md).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "sim/record.hpp"
#include "tools/ftsim/commands.hpp"

namespace ftstack::tools {
namespace {

struct RecordOptions {
  std::string sensor = "builtin";
  std::string profile = "rig";
  std::string out;
  std::string sim_out;
  std::string truth;
  std::vector<std::string> effects;
  double rate_hz = 0.0;
  double duration_s = 0.0;
  std::uint64_t seed = 1;
  double noise_mvv = NAN;
  bool no_temp = false;
};

void Run(const RecordOptions& o, bool noise_given) {
  sim::RecordRequest req;
  req.sensor = sim::LoadSensorDescription(o.sensor);
  req.profile = o.profile;
  req.rate_hz = o.rate_hz;
  req.duration_s = o.duration_s;
  req.seed = o.seed;
  if (noise_given) req.noise_mvv = o.noise_mvv;
  req.effects = sim::ParseEffects(o.effects);
  req.temperature = !o.no_temp;
  const sim::RecordResult res = sim::MakeRecording(req);
  WriteRecording(o.out, res.real);
  if (!o.sim_out.empty()) WriteRecording(o.sim_out, res.sim);
  if (!o.truth.empty()) sim::WriteTruth(o.truth, res.truth);
}

}  // namespace

void AddRecordCommand(CLI::App& app, int* exit_code) {
  auto opt = std::make_shared<RecordOptions>();
  auto* cmd = app.add_subcommand(
      "record", "simulated recording of a load profile, with injected effects (docs/effects.md)");
  cmd->add_option("--sensor", opt->sensor, "sensor description JSON, or 'builtin'");
  cmd->add_option("--profile", opt->profile,
                  "rig | taps | thermal | hold | base-pick | base-tilt | base-estop | PROFILE.json "
                  "(keyframes) | REC.csv (wrench columns)");
  cmd->add_option("--out", opt->out, "the 'real' recording (effects, noise, quantisation)")
      ->required();
  cmd->add_option("--sim-out", opt->sim_out, "the model's noise-free prediction without effects");
  cmd->add_option("--truth", opt->truth, "JSON of the injected effects, parameters and footprint");
  cmd->add_option("--effect", opt->effects, "NAME[:k=v,...] (repeatable); lists as [a,b] or a/b");
  cmd->add_option("--rate-hz", opt->rate_hz, "sample rate (default: the profile's, 200 or 100 Hz)");
  cmd->add_option("--duration-s", opt->duration_s, "length (default: the profile's own)");
  cmd->add_option("--seed", opt->seed, "random seed (profile variations, defaults, noise)");
  auto* noise =
      cmd->add_option("--noise-mvv", opt->noise_mvv, "ADC noise, mV/V RMS (default: the sensor's)");
  cmd->add_flag("--no-temp", opt->no_temp, "omit the temp_C column");
  cmd->callback([opt, noise, exit_code] {
    Run(*opt, noise->count() > 0);
    *exit_code = kExitOk;
  });
}

}  // namespace ftstack::tools
