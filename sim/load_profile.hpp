// Load profiles for simulated recordings: calibration rig, taps, thermal, hold, or from a file.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// A profile that cannot be built or read; what() names the file (line:column where one applies).
class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Deterministic uniform/normal numbers from a seed (SplitMix64), identical on every platform.
class SeededRandom {
 public:
  explicit SeededRandom(std::uint64_t seed) : state_(seed) {}
  [[nodiscard]] std::uint64_t Next();
  /// Uniform in [lo, hi).
  [[nodiscard]] double Uniform(double lo = 0.0, double hi = 1.0);
  /// Standard normal (Box–Muller).
  [[nodiscard]] double Normal();
  /// Uniform integer in [0, n).
  [[nodiscard]] int Index(int n);

 private:
  std::uint64_t state_;
};

/// Applied load and body temperature as continuous functions of time: piecewise linear between
/// load keyframes (t_s strictly increasing) and between temperature keyframes. Before the first
/// keyframe the first value holds, after the last the last one.
class LoadProfile {
 public:
  LoadProfile() = default;
  LoadProfile(std::string name, std::vector<double> load_t_s, std::vector<Wrench> load,
              std::vector<double> temp_t_s, std::vector<double> temp_c, double duration_s,
              double default_rate_hz);

  /// Wrench (N, N·m) at time t_s.
  [[nodiscard]] Wrench LoadAt(double t_s) const;
  /// Body temperature (°C) at time t_s.
  [[nodiscard]] double TemperatureAt(double t_s) const;
  /// Replaces the load on [t0_s, t1_s] by the given keyframes (times inside [t0_s, t1_s]); used to
  /// insert events such as an overload.
  void Splice(double t0_s, double t1_s, const std::vector<double>& t_s,
              const std::vector<Wrench>& w);

  /// Adds a tool vibration: amplitude(t)·sin(2π·freq_hz·t), the amplitude (N, N·m peak per axis)
  /// piecewise linear between its keyframes as the load is.
  void SetVibration(double freq_hz, std::vector<double> amplitude_t_s,
                    std::vector<Wrench> amplitude);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] double duration_s() const { return duration_s_; }
  [[nodiscard]] double default_rate_hz() const { return default_rate_hz_; }
  [[nodiscard]] const std::vector<double>& key_times_s() const { return load_t_; }
  [[nodiscard]] const std::vector<Wrench>& key_loads() const { return load_; }

 private:
  std::string name_;
  std::vector<double> load_t_;
  std::vector<Wrench> load_;
  std::vector<double> temp_t_;
  std::vector<double> temp_c_;
  double duration_s_ = 0.0;
  double default_rate_hz_ = 200.0;
  double vibration_hz_ = 0.0;
  std::vector<double> vibration_t_;
  std::vector<Wrench> vibration_;
};

/// Builds a profile. `spec` is one of
///   rig      calibration rig: ± steps and up/down staircase sweeps on each axis, axial preload
///            combined with each bending/shear load, random combined wrenches, fast taps; lab
///            temperature wandering ±0.4 K (≈ 250 s at 200 Hz per cycle)
///   taps     fast load changes (5 ms edges) on random axes and combinations (60 s, 200 Hz)
///   thermal  the rig sequence while the body warms by ≈ 8 K: an ambient rise plus self-heating
///            that follows the load intensity (correlated with the load sequence)
///   hold     sustained loads of 40–60 s each followed by 40–60 s unloaded (≈ 500 s at 100 Hz)
///   base-pick, base-tilt, base-estop
///            a sensor under a robot's base: the arm's weight (Fz −43 % of rated) with four
///            pick-and-place reaches (≈ 10 s, 200 Hz); slow tilting to 55 % of the tilt rating
///            (≈ 24 s, 200 Hz); pick-and-place then an emergency stop in which every component
///            reaches its rated value within 20 ms and rings down at 8 Hz (≈ 14 s, 1 kHz). On a
///            sensor rated at the Panda base figures (300/410 N, 280/190 N·m) these are them.
///   work:NAME  a robot or machine work cycle (sim/work_cycles.hpp: machine-tending, palletising,
///            assembly, polishing, hand-guiding, screwdriving, night-idle); 24 h at 1 kHz
///   PATH     (or file:PATH) a JSON keyframe file (schema "ftstack-profile/1": {"keyframes":
///            [{"t_s", "wrench": [6], "temp_C"}], "rate_hz"}) or a recording CSV with t and the
///            wrench columns (temp_C optional)
/// Generated profiles are deterministic per seed. `duration_s` > 0 repeats (new random cycle) or
/// cuts the sequence to that length; 0 keeps the profile's natural length. `rated` scales loads.
[[nodiscard]] LoadProfile MakeProfile(const std::string& spec, const Wrench& rated,
                                      std::uint64_t seed, double duration_s = 0.0);

/// The JSON keyframe form of MakeProfile's PATH from its text; `path` names it in errors
/// (path:line:column). What MakeProfile does with a .json file after reading it.
[[nodiscard]] LoadProfile ParseProfileJson(const std::string& text, const std::string& path,
                                           double duration_s = 0.0);

}  // namespace ftstack::sim
