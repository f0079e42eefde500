// Integer signal blocks of the health watch: tone amplitude (Goertzel), noise, ringing frequency.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ftstack::fw {

/// One Goertzel tone detector on the first difference of a signal (a ramp is a constant there, so
/// moving loads leak nothing into the tone). Coefficient and gain are fixed at Configure (doubles
/// once at start-up); Add is integer only. The block length should hold whole periods of the tone.
class ToneDetector {
 public:
  /// Tone `freq_hz` at `rate_hz` over blocks of `block` samples. False if the tone is not below
  /// the Nyquist frequency or the block is shorter than 8 samples.
  [[nodiscard]] bool Configure(std::uint32_t freq_hz, std::uint32_t rate_hz, std::uint32_t block);
  /// One first difference d (clamped by the caller to ±max_diff()).
  void Add(std::int32_t d) {
    const std::int64_t s0 = d + ((coef_q30_ * s1_) >> 30) - s2_;
    s2_ = s1_;
    s1_ = s0;
  }
  /// The block's tone amplitude in the original signal (peak, Q8 LSB) and the mean square of the
  /// difference signal this tone explains (Q8 LSB²); restarts the detector.
  void Finish(std::int64_t* amplitude_q8, std::int64_t* diff_power_q8);
  /// The largest |d| for which no sum overflows 64 bits at this rate and block: the
  /// resonator grows to at most N · min(N, 1/sin ω) · |d|.
  [[nodiscard]] std::int32_t max_diff() const { return max_diff_; }

 private:
  std::int64_t coef_q30_ = 0;  ///< 2·cos(2π f / rate), Q30
  std::int64_t gain_q16_ = 0;  ///< 1 / (N · sin(π f / rate)), Q16: |X| → amplitude
  std::uint32_t block_ = 0;
  std::int32_t max_diff_ = 1 << 15;
  std::int64_t s1_ = 0;
  std::int64_t s2_ = 0;
};

/// A ringing frequency read from a captured transient: the level is the mean of the capture's last
/// quarter; zero crossings are counted with a Schmitt trigger of ±hysteresis around it. No
/// frequency when that quarter is no level (its halves' means differ by more than the hysteresis
/// plus a quarter of the amplitude): the load was still moving, and its own swings were counted.
struct RingingResult {
  std::int32_t freq_mhz = 0;    ///< 0: fewer than 4 crossings or no level (no ringing measured)
  std::int32_t amplitude = 0;   ///< largest |x − level| after the first crossing, LSB
  std::uint16_t crossings = 0;  ///< Schmitt-trigger crossings counted
};
/// `x` holds `n` samples taken at `rate_hz` (integer LSB).
[[nodiscard]] RingingResult MeasureRinging(const std::int32_t* x, std::size_t n,
                                           std::uint32_t rate_hz, std::int32_t hysteresis);

/// MeasureRinging in slices, so that no single sample pays for a whole capture: Start, then
/// Advance until it returns true; result() is then MeasureRinging's. `x` must stay unchanged
/// until then.
class RingingScan {
 public:
  void Start(const std::int32_t* x, std::size_t n, std::uint32_t rate_hz, std::int32_t hysteresis);
  /// Works on at most `budget` (≥ 1) more samples: the level's quarter first, then the crossings.
  /// True once the result is final (also when nothing was started).
  [[nodiscard]] bool Advance(std::size_t budget);
  [[nodiscard]] const RingingResult& result() const { return r_; }

 private:
  enum class Phase : std::uint8_t { kDone, kLevel, kScan };
  void Finish();

  const std::int32_t* x_ = nullptr;
  std::size_t n_ = 0;
  std::size_t tail_ = 0;
  std::size_t i_ = 0;
  std::int64_t sum_ = 0;
  std::int64_t late_sum_ = 0;     // Σ of the last quarter's second half
  std::int64_t level_moved_ = 0;  // that half's mean less the first half's
  std::int64_t level_ = 0;
  std::int64_t first_q8_ = 0;
  std::int64_t last_q8_ = 0;
  std::int64_t peak_ = 0;
  std::int64_t zero_q8_ = 0;  // the latest sign change of x − level, Q8 samples (interpolated)
  std::int64_t prev_ = 0;
  std::int64_t lobe_ = 0;  // the largest |x − level| since the last crossing
  std::uint32_t rate_hz_ = 0;
  std::int32_t hysteresis_ = 0;
  int side_ = 0;  // +1 above level + h, −1 below level − h, 0 not yet known
  Phase phase_ = Phase::kDone;
  RingingResult r_{};
};

/// Creep estimate from the means of three equal, consecutive segments of a hold: with d1 = m2 − m1
/// and d2 = m3 − m2 of an exponential approach, the creep still to come after m1's middle is
/// d1² / (d1 − d2); d1 + d2 (what was seen) when the increments do not decay.
[[nodiscard]] std::int64_t CreepRemaining(std::int64_t m1, std::int64_t m2, std::int64_t m3);

}  // namespace ftstack::fw
