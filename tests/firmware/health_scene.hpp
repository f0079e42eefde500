// Synthetic scenes for the health watch's tests: a load written as a function of time, noise,
// and a runner that feeds the watch sample by sample.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>

#include "firmware/health_watch.hpp"

namespace ftstack::fw {

inline constexpr WrenchLsb kRated = {200000,  200000,  400000,
                                     1000000, 1000000, 800000};  // 200 N … 8 N·m

/// Cheap Gaussian noise (Irwin–Hall of 4 uniforms from xorshift64): unit variance.
class Noise {
 public:
  double Next() {
    double s = 0;
    for (int i = 0; i < 4; ++i) {
      state_ ^= state_ << 13;
      state_ ^= state_ >> 7;
      state_ ^= state_ << 17;
      s += static_cast<double>(state_ >> 11) * (1.0 / 9007199254740992.0);
    }
    return (s - 2.0) * std::sqrt(3.0);
  }

 private:
  std::uint64_t state_ = 0x9E3779B97F4A7C15ull;
};

/// A scene: the tared load (N·m units as LSB) and temperature as functions of time.
struct Scene {
  std::uint32_t rate = 1000;
  double noise_fraction = 5e-5;  ///< noise σ as a fraction of rated
  std::function<void(double t, std::array<double, 6>& y, double& temp_c)> load;
  std::function<std::uint16_t(double t)> status;  ///< the device's status bits (none: 0)
};

class Runner {
 public:
  explicit Runner(const Scene& s, HealthThresholds th = {}) : scene_(s) {
    EXPECT_TRUE(watch_.Configure(s.rate, kRated));
    watch_.SetThresholds(th);
  }
  /// Runs until t_end_s; `each_second` is called once per simulated second.
  void Run(double t_end_s, const std::function<void(double)>& each_second = nullptr) {
    const auto end = static_cast<std::uint64_t>(t_end_s * scene_.rate);
    for (; n_ < end; ++n_) {
      const double t = static_cast<double>(n_) / scene_.rate;
      std::array<double, 6> y{};
      double temp = 20.0;
      scene_.load(t, y, temp);
      HealthInput in;
      in.valid = true;
      in.has_temperature = true;
      in.temperature_mdegc = static_cast<std::int32_t>(std::lround(temp * 1000));
      for (std::size_t r = 0; r < 6; ++r) {
        in.tared[r] = static_cast<std::int32_t>(
            std::lround(y[r] + noise_.Next() * scene_.noise_fraction * kRated[r]));
      }
      in.untared = in.tared;  // no tare in the scenes: the load is the output
      in.untared_valid = true;
      if (scene_.status) in.status = scene_.status(t);
      watch_.Step(in);
      if (each_second && n_ % scene_.rate == 0) each_second(t);
    }
  }
  HealthWatch& watch() { return watch_; }
  [[nodiscard]] const HealthReport& report() const { return watch_.report(); }

 private:
  Scene scene_;
  HealthWatch watch_;
  Noise noise_;
  std::uint64_t n_ = 0;
};

inline bool Has(const HealthReport& r, HealthCause c) {
  return (r.findings & (1u << (static_cast<int>(c) - 1))) != 0;
}
inline const HealthFinding* Slot(const HealthReport& r, HealthCause c) {
  for (const HealthFinding& f : r.slots) {
    if (f.cause == c) return &f;
  }
  return nullptr;
}

}  // namespace ftstack::fw
