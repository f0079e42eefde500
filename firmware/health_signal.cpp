#include "firmware/health_signal.hpp"

#include <algorithm>
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
  // coef·s within 2^62 (|s| ≤ 2^31) and the block's (Σd)² · 256 within 2^63 (|Σd| ≤ 2^27).
  const double growth = block * std::min<double>(block, 1.0 / std::fabs(std::sin(w)));
  const double limit = std::min({2147483648.0 / growth, 134217728.0 / block, 16777216.0});
  max_diff_ = static_cast<std::int32_t>(std::max(limit, 1.0));
  s1_ = 0;
  s2_ = 0;
  return true;
}

void ToneDetector::Finish(std::int64_t* amplitude_q8, std::int64_t* diff_power_q8) {
  // |X|² = s1² + s2² − c·s1·s2 (the Goertzel power at the tone); bounded by (N·max_diff)².
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
  RingingScan scan;
  scan.Start(x, n, rate_hz, hysteresis);
  while (!scan.Advance(n)) {
  }
  return scan.result();
}

void RingingScan::Start(const std::int32_t* x, std::size_t n, std::uint32_t rate_hz,
                        std::int32_t hysteresis) {
  *this = RingingScan{};
  if (x == nullptr || n < 16 || rate_hz == 0 || hysteresis < 1) return;  // kDone, no ringing
  x_ = x;
  n_ = n;
  tail_ = n / 4;
  i_ = n - tail_;
  rate_hz_ = rate_hz;
  hysteresis_ = hysteresis;
  phase_ = Phase::kLevel;
}

bool RingingScan::Advance(std::size_t budget) {
  if (phase_ == Phase::kLevel) {
    const std::size_t end = n_ - i_ > budget ? i_ + budget : n_;
    const std::size_t late = n_ - tail_ / 2;
    for (; i_ < end; ++i_) {
      sum_ += x_[i_];
      if (i_ >= late) late_sum_ += x_[i_];
    }
    if (i_ < n_) return false;
    level_ = sum_ / static_cast<std::int64_t>(tail_);
    const auto late_n = static_cast<std::int64_t>(tail_ / 2);
    level_moved_ =
        late_sum_ / late_n - (sum_ - late_sum_) / (static_cast<std::int64_t>(tail_) - late_n);
    prev_ = x_[0] - level_;
    i_ = 0;
    phase_ = Phase::kScan;
    return false;
  }
  if (phase_ != Phase::kScan) return true;
  const std::size_t stop = n_ - tail_;
  const std::size_t end = stop - i_ > budget ? i_ + budget : stop;
  const std::int64_t h = hysteresis_;
  for (; i_ < end; ++i_) {
    const std::int64_t v = x_[i_] - level_;
    if (i_ > 0 && (v >= 0) != (prev_ >= 0)) {
      zero_q8_ = static_cast<std::int64_t>(i_ - 1) * 256 + (-prev_ * 256) / (v - prev_);
    }
    prev_ = v;
    const std::int64_t mag = v < 0 ? -v : v;
    const int now = v > h ? 1 : (v < -h ? -1 : 0);
    // A crossing confirmed by the hysteresis is dated at its sign change (no amplitude bias).
    // Counting ends at the first lobe under 3 hysteresis bands: past it a lobe lost in the noise
    // would drop a whole period from the count.
    if (now != 0 && side_ != 0 && now != side_) {
      if (r_.crossings > 0 && lobe_ < 3 * h) {
        Finish();
        return true;
      }
      if (r_.crossings == 0) first_q8_ = zero_q8_;
      last_q8_ = zero_q8_;
      ++r_.crossings;
      lobe_ = 0;
    }
    if (mag > lobe_) lobe_ = mag;
    if (now != 0) side_ = now;
    if (r_.crossings > 0 && mag > peak_) peak_ = mag;
  }
  if (i_ < stop) return false;
  Finish();
  return true;
}

void RingingScan::Finish() {
  phase_ = Phase::kDone;
  r_.amplitude = static_cast<std::int32_t>(peak_);
  if (r_.crossings < 4 || last_q8_ <= first_q8_) return;
  // A step response ends on a level: a decaying ringing moves its last quarter's halves' means
  // by a fraction of its largest lobe; beyond a quarter of it (plus the hysteresis) the load
  // itself still moves (a bounce, a ramp) and its swings are not the mount's ringing.
  const std::int64_t moved = level_moved_ < 0 ? -level_moved_ : level_moved_;
  if (moved > hysteresis_ + peak_ / 4) return;
  // (crossings − 1) half periods between the first and the last crossing.
  const std::uint64_t num = static_cast<std::uint64_t>(r_.crossings - 1) * rate_hz_ * 256000u;
  const std::uint64_t span = static_cast<std::uint64_t>(last_q8_ - first_q8_);
  r_.freq_mhz = static_cast<std::int32_t>((num + span) / (2u * span));
}

std::int64_t CreepRemaining(std::int64_t m1, std::int64_t m2, std::int64_t m3) {
  const std::int64_t d1 = m2 - m1;
  const std::int64_t d2 = m3 - m2;
  const bool decays = d1 != 0 && ((d1 > 0 && d2 >= 0 && d2 < d1) || (d1 < 0 && d2 <= 0 && d2 > d1));
  if (!decays) return d1 + d2;
  return static_cast<std::int64_t>(static_cast<Int128>(d1) * d1 / (d1 - d2));
}

}  // namespace ftstack::fw
