#include "firmware/health_signal.hpp"

#include <cmath>

#include "firmware/overload.hpp"

namespace ftstack::fw {
namespace {

__extension__ using Int128 = __int128;

/// sqrt(p) in Q8 (p ≥ 0), as exact as 64 bits allow.
[[nodiscard]] std::int64_t SqrtQ8(std::uint64_t p) {
  if (p < (std::uint64_t{1} << 46)) return ISqrt64(p << 16);
  return static_cast<std::int64_t>(ISqrt64(p)) << 8;
}

}  // namespace

bool ToneDetector::Configure(std::uint32_t freq_hz, std::uint32_t rate_hz, std::uint32_t block) {
  if (rate_hz == 0 || 2u * freq_hz >= rate_hz || block < 8) return false;
  // Start-up only: the two constants in double, rounded once.
  const double w = 2.0 * M_PI * freq_hz / rate_hz;
  coef_q30_ = std::llround(2.0 * std::cos(w) * 1073741824.0);
  gain_q16_ = std::llround(65536.0 / (block * std::sin(w / 2.0)));
  block_ = block;
  s1_ = 0;
  s2_ = 0;
  return true;
}

void ToneDetector::Finish(std::int64_t* amplitude_q8, std::int64_t* diff_power_q8) {
  // |X|² = s1² + s2² − c·s1·s2 (the Goertzel power at the tone); bounded by (N·kMaxDiff)².
  const Int128 p = static_cast<Int128>(s1_) * s1_ + static_cast<Int128>(s2_) * s2_ -
                   ((static_cast<Int128>(coef_q30_) * s1_ * s2_) >> 30);
  const std::uint64_t pu =
      p <= 0 ? 0 : (p > static_cast<Int128>(INT64_MAX) ? INT64_MAX : static_cast<std::uint64_t>(p));
  // Amplitude of the difference signal 2|X|/N; of the signal itself ÷ 2 sin(π f / rate).
  *amplitude_q8 = (SqrtQ8(pu) * gain_q16_) >> 16;
  // The tone's share of the difference's mean square: (2|X|/N)² / 2.
  const Int128 n2 = static_cast<Int128>(block_) * block_;
  *diff_power_q8 = static_cast<std::int64_t>((static_cast<Int128>(pu) * 512) / n2);
  s1_ = 0;
  s2_ = 0;
}

RingingResult MeasureRinging(const std::int32_t* x, std::size_t n, std::uint32_t rate_hz,
                             std::int32_t hysteresis) {
  RingingResult r{};
  if (n < 16 || rate_hz == 0 || hysteresis < 1) return r;
  std::int64_t sum = 0;
  const std::size_t tail = n / 4;
  for (std::size_t i = n - tail; i < n; ++i) sum += x[i];
  const std::int64_t level = sum / static_cast<std::int64_t>(tail);
  int side = 0;  // +1 above level + h, −1 below level − h, 0 not yet known
  std::int64_t first_q8 = 0;
  std::int64_t last_q8 = 0;
  std::int64_t peak = 0;
  std::int64_t zero_q8 = 0;  // the latest sign change of x − level, Q8 samples (interpolated)
  std::int64_t prev = x[0] - level;
  std::int64_t lobe = 0;  // the largest |x − level| since the last crossing
  for (std::size_t i = 0; i < n - tail; ++i) {
    const std::int64_t v = x[i] - level;
    if (i > 0 && (v >= 0) != (prev >= 0)) {
      zero_q8 = static_cast<std::int64_t>(i - 1) * 256 + (-prev * 256) / (v - prev);
    }
    prev = v;
    const std::int64_t mag = v < 0 ? -v : v;
    const int now = v > hysteresis ? 1 : (v < -hysteresis ? -1 : 0);
    // A crossing confirmed by the hysteresis is dated at its sign change (no amplitude bias).
    // Counting ends at the first lobe under 3 hysteresis bands: past it a lobe lost in the noise
    // would drop a whole period from the count.
    if (now != 0 && side != 0 && now != side) {
      if (r.crossings > 0 && lobe < 3 * std::int64_t{hysteresis}) break;
      if (r.crossings == 0) first_q8 = zero_q8;
      last_q8 = zero_q8;
      ++r.crossings;
      lobe = 0;
    }
    if (mag > lobe) lobe = mag;
    if (now != 0) side = now;
    if (r.crossings > 0 && (v < 0 ? -v : v) > peak) peak = v < 0 ? -v : v;
  }
  r.amplitude = static_cast<std::int32_t>(peak);
  if (r.crossings < 4 || last_q8 <= first_q8) return r;
  // (crossings − 1) half periods between the first and the last crossing.
  const std::uint64_t num = static_cast<std::uint64_t>(r.crossings - 1) * rate_hz * 256000u;
  const std::uint64_t span = static_cast<std::uint64_t>(last_q8 - first_q8);
  r.freq_mhz = static_cast<std::int32_t>((num + span) / (2u * span));
  return r;
}

std::int64_t CreepRemaining(std::int64_t m1, std::int64_t m2, std::int64_t m3) {
  const std::int64_t d1 = m2 - m1;
  const std::int64_t d2 = m3 - m2;
  const bool decays = d1 != 0 && ((d1 > 0 && d2 >= 0 && d2 < d1) || (d1 < 0 && d2 <= 0 && d2 > d1));
  if (!decays) return d1 + d2;
  return static_cast<std::int64_t>(static_cast<Int128>(d1) * d1 / (d1 - d2));
}

}  // namespace ftstack::fw
