// Wrench sources that drive a simulated sensor: constant, piecewise-linear profile, recording
// replay.
#pragma once

#include <memory>
#include <vector>

#include "measurement/recording.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// Applied load (and body temperature) as a function of time.
class WrenchSource {
 public:
  virtual ~WrenchSource() = default;
  /// Wrench at time t_s; false once the source is exhausted (end of a replay).
  [[nodiscard]] virtual bool At(double t_s, Wrench* w, double* temperature_c) const = 0;
};

/// The same wrench forever.
class ConstantWrench final : public WrenchSource {
 public:
  explicit ConstantWrench(const Wrench& w, double temperature_c = 20.0)
      : w_(w), temperature_c_(temperature_c) {}
  [[nodiscard]] bool At(double t_s, Wrench* w, double* temperature_c) const override;

 private:
  Wrench w_;
  double temperature_c_;
};

/// Linear interpolation between keyframes (t strictly increasing); holds the last one after the
/// end unless `finite`.
class ProfileWrench final : public WrenchSource {
 public:
  struct Key {
    double t_s;
    Wrench w;
    double temperature_c = 20.0;
  };
  explicit ProfileWrench(std::vector<Key> keys, bool finite = false);
  [[nodiscard]] bool At(double t_s, Wrench* w, double* temperature_c) const override;
  [[nodiscard]] double duration_s() const { return keys_.back().t_s; }

 private:
  std::vector<Key> keys_;
  bool finite_;
};

/// Plays the wrench columns (and temp_C where present) of a recording, linearly interpolated in t;
/// exhausted after its last row.
std::unique_ptr<ProfileWrench> ReplayWrench(const Recording& rec);

}  // namespace ftstack::sim
