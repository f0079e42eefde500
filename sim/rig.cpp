#include "sim/rig.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "hal/sim/sim_adc.hpp"
#include "measurement/wrench.hpp"
#include "sim/simulated_sensor.hpp"

namespace ftstack::sim {
namespace {

std::string Pct(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.0f%%", f * 100.0);
  return buf;
}

void SingleAxisSweeps(const Wrench& rated, const std::vector<double>& levels, double temp,
                      std::vector<RigStep>* out) {
  for (int a = 0; a < 6; ++a) {
    for (double sign : {1.0, -1.0}) {
      std::vector<double> seq = levels;                                                   // up …
      for (auto it = levels.rbegin() + 1; it != levels.rend(); ++it) seq.push_back(*it);  // … down
      seq.push_back(0.0);
      for (std::size_t i = 0; i < seq.size(); ++i) {
        RigStep s;
        s.wrench(a) = sign * seq[i] * rated(a);
        s.temperature_c = temp;
        s.label = std::string(kWrenchAxisNames[a]) + " " + Pct(sign * seq[i]) +
                  (i < levels.size() ? " up" : " down");
        out->push_back(s);
      }
    }
  }
}

void Combined(const Wrench& rated, double temp, std::vector<RigStep>* out) {
  // Axial preload × bending, lever loads (F_x with M_y, F_y with M_x), shear × torsion.
  const int pairs[][2] = {{2, 3}, {2, 4}, {2, 5}, {0, 4}, {1, 3}, {0, 5}, {1, 5}, {0, 1}, {3, 4}};
  for (const auto& p : pairs) {
    for (double sa : {0.5, -0.5}) {
      for (double sb : {0.5, -0.5}) {
        RigStep s;
        s.wrench(p[0]) = sa * rated(p[0]);
        s.wrench(p[1]) = sb * rated(p[1]);
        s.temperature_c = temp;
        s.label = std::string(kWrenchAxisNames[p[0]]) + " " + Pct(sa) + " x " +
                  kWrenchAxisNames[p[1]] + " " + Pct(sb);
        out->push_back(s);
      }
    }
  }
}

}  // namespace

std::vector<RigStep> DesignRig(const Wrench& rated, const RigDesignOptions& options) {
  for (int a = 0; a < 6; ++a) {
    if (!(rated(a) > 0) || !std::isfinite(rated(a))) {
      throw std::invalid_argument("rated range must be positive on every axis");
    }
  }
  std::vector<double> temps = options.temperatures_c;
  if (temps.empty()) temps.push_back(20.0);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<RigStep> steps;
  for (std::size_t ti = 0; ti < temps.size(); ++ti) {
    const double temp = temps[ti];
    RigStep zero;
    zero.temperature_c = temp;
    zero.label = "zero";
    steps.push_back(zero);
    SingleAxisSweeps(rated, ti == 0 ? options.levels : std::vector<double>{1.0}, temp, &steps);
    if (options.combined) Combined(rated, temp, &steps);
    for (int i = 0; i < options.random_combinations; ++i) {
      RigStep s;
      for (int a = 0; a < 6; ++a) s.wrench(a) = u(rng) * rated(a);
      s.temperature_c = temp;
      s.label = "mixed " + std::to_string(i + 1);
      steps.push_back(s);
    }
    steps.push_back(zero);
  }
  return steps;
}

std::vector<sim::ProfileWrench::Key> RigKeys(const std::vector<RigStep>& steps,
                                             const RigDesignOptions& options) {
  if (!(options.hold_s > 0) || !(options.ramp_s > 0)) {
    throw std::invalid_argument("hold and ramp times must be positive");
  }
  std::vector<sim::ProfileWrench::Key> keys;
  double t = 0.0;
  for (const RigStep& s : steps) {
    keys.push_back({t, s.wrench, s.temperature_c});
    keys.push_back({t + options.hold_s, s.wrench, s.temperature_c});
    t += options.hold_s + options.ramp_s;
  }
  return keys;
}

Recording SimulateRig(const sim::SensorDescription& sensor,
                      const std::vector<sim::ProfileWrench::Key>& keys, double rate_hz,
                      std::uint64_t seed, bool with_pose) {
  if (keys.empty()) throw std::invalid_argument("empty rig sequence");
  const sim::ProfileWrench profile(keys, true);
  hal::sim::SimAdcParams params = sensor.adc;
  params.seed = seed;
  params.realtime = false;
  sim::SimulatedAdc simulated(sensor, profile, params);
  const sim::SimulatedSensor& source = simulated.sensor();
  hal::sim::SimAdc& adc = simulated.adc();
  const hal::AdcConfig cfg = simulated.Config(static_cast<std::uint32_t>(std::lround(rate_hz)));
  if (adc.Configure(cfg) != hal::Status::kOk) {
    throw std::invalid_argument("simulated ADC refused the configuration");
  }
  const double cpm = adc.counts_per_mvv();
  const std::size_t n = cfg.channel_count;
  const auto rows = static_cast<std::size_t>(std::floor(profile.duration_s() * rate_hz)) + 1;
  std::vector<std::vector<double>> cols(7 + n + 1 + (with_pose ? 1 : 0));
  for (auto& c : cols) c.reserve(rows);
  std::size_t pose = 0;
  hal::AdcSample s{};
  for (std::size_t i = 0; i < rows; ++i) {
    if (adc.WaitDataReady(1000000) != hal::Status::kOk || adc.Read(s) != hal::Status::kOk) break;
    const double t = static_cast<double>(i) / static_cast<double>(cfg.rate_hz);
    cols[0].push_back(t);
    const Wrench& w = source.last_wrench();
    for (int a = 0; a < 6; ++a) cols[static_cast<std::size_t>(1 + a)].push_back(w(a));
    for (std::size_t c = 0; c < n; ++c) cols[7 + c].push_back(s.counts[c] / cpm);
    cols[7 + n].push_back(s.has_temperature ? s.temperature_mdegc / 1000.0 : 20.0);
    if (with_pose) {
      // Keys come in pairs (hold start, hold end); a transition belongs to the nearer hold.
      while (2 * pose + 2 < keys.size() &&
             t >= 0.5 * (keys[2 * pose + 1].t_s + keys[2 * pose + 2].t_s)) {
        ++pose;
      }
      cols[8 + n].push_back(static_cast<double>(pose));
    }
  }
  Recording rec;
  rec.path = "(simulated rig)";
  rec.metadata.push_back("sensor: " + sensor.name);
  rec.metadata.push_back("source: ftcal design (simulated rig)");
  rec.names = {"t"};
  rec.names.insert(rec.names.end(), kWrenchAxisNames.begin(), kWrenchAxisNames.end());
  for (const auto& b : BridgeColumns(n)) rec.names.push_back(b);
  rec.names.push_back("temp_C");
  if (with_pose) rec.names.push_back("pose");
  rec.columns = std::move(cols);
  return rec;
}

std::vector<Wrench> RigLoads(const std::vector<RigStep>& steps) {
  std::vector<Wrench> loads;
  loads.reserve(steps.size());
  for (const RigStep& s : steps) loads.push_back(s.wrench);
  return loads;
}

std::string RigStepTable(const std::vector<RigStep>& steps) {
  std::string out;
  char line[256];
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Wrench& w = steps[i].wrench;
    std::snprintf(line, sizeof line, "%4zu  %-28s  %8.2f %8.2f %8.2f %7.3f %7.3f %7.3f  %5.1f C\n",
                  i, steps[i].label.c_str(), w(0), w(1), w(2), w(3), w(4), w(5),
                  steps[i].temperature_c);
    out += line;
  }
  return out;
}

Recording RigProfileRecording(const std::vector<ProfileWrench::Key>& keys) {
  Recording prof;
  prof.names = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "temp_C"};
  prof.columns.resize(8);
  for (const auto& k : keys) {
    prof.columns[0].push_back(k.t_s);
    for (int a = 0; a < 6; ++a) prof.columns[static_cast<std::size_t>(1 + a)].push_back(k.w(a));
    prof.columns[7].push_back(k.temperature_c);
  }
  prof.metadata.push_back("source: ftcal design");
  return prof;
}

}  // namespace ftstack::sim
