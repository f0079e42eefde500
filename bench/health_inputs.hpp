// The health watch's benchmark input, shared by bench_health (time) and count_health
// (instructions): a realistic load with noise, load steps and ringing.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "firmware/health_watch.hpp"

namespace ftstack::bench {

using fw::HealthInput;
using fw::WrenchLsb;

/// The built-in sensor's rated range in LSB (mN, 0.01 mN·m).
inline constexpr WrenchLsb kHealthRated = {200000, 200000, 400000, 1000000, 1000000, 800000};

/// 4 s of input at `rate`: ± noise, Fz stepping to 40 % of rated at 1 s and back at 3 s, each
/// step ringing at 25 Hz (ζ = 0.04, 1 % of the step).
inline std::vector<HealthInput> HealthInputs(std::uint32_t rate) {
  std::vector<HealthInput> v(4 * rate);
  std::uint64_t s = 88172645463325252ull;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double t = static_cast<double>(i) / rate;
    const double on = t >= 1.0 && t < 3.0 ? 1.0 : 0.0;
    const double since = t >= 3.0 ? t - 3.0 : (t >= 1.0 ? t - 1.0 : 10.0);
    const double wn = 2 * M_PI * 25.0;
    const double ring =
        0.01 * std::exp(-0.04 * wn * since) * std::cos(wn * since) * (t >= 3.0 ? -1.0 : 1.0);
    HealthInput& in = v[i];
    in.valid = true;
    in.has_temperature = true;
    in.temperature_mdegc = 21000;
    for (std::size_t r = 0; r < 6; ++r) {
      s ^= s << 13;
      s ^= s >> 7;
      s ^= s << 17;
      in.tared[r] = static_cast<std::int32_t>((s >> 40) % 41) - 20;
    }
    in.tared[2] += static_cast<std::int32_t>(std::lround((on + ring) * 0.4 * kHealthRated[2]));
    in.untared = in.tared;  // the rainflow counters run too
    in.untared_valid = true;
  }
  return v;
}

/// A 512-sample capture ringing at 25 Hz at 1 kHz on a 40 %-of-rated level: the input of the
/// watch's worst sample (one MeasureRinging).
inline std::vector<std::int32_t> RingingCapture() {
  std::vector<std::int32_t> x(fw::HealthWatch::kRingCapture);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i) / 1000.0;
    x[i] = static_cast<std::int32_t>(160000 + 1600 * std::exp(-6.3 * t) * std::cos(157 * t));
  }
  return x;
}

}  // namespace ftstack::bench
