// Combined-load overload detection in fixed point, with event counter and per-axis peak loads.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"

namespace ftstack::fw {

/// Largest rated range per axis the fixed-point rule accepts, LSB (134 kN, 1342 N·m).
inline constexpr std::int32_t kMaxRatedLsb = std::int32_t{1} << 27;
/// Load shares are fractions of the rated range in Q24 (1.0 = 1 << 24).
inline constexpr std::uint32_t kShareOne = 1u << 24;
/// Overload threshold: 105 % of the rated range, Q24 (rounded up: > 1.05 strictly).
inline constexpr std::uint64_t kOverloadShareNum = 21;  ///< 1.05 = 21 / 20
inline constexpr std::uint64_t kOverloadShareDen = 20;
/// Release threshold: an overload event ends only when both shares are at or below 100 % of the
/// rated range (hysteresis: noise around 105 % does not count one event per crossing).
inline constexpr std::uint64_t kReleaseShareNum = 1;
inline constexpr std::uint64_t kReleaseShareDen = 1;

/// floor(sqrt(n)) for any 64-bit n (bit-by-bit, integer only).
[[nodiscard]] std::uint32_t ISqrt64(std::uint64_t n);

/// Load shares of one sensor-frame wrench, Q24 fractions of rated.
struct LoadShares {
  std::uint32_t fxy_mz = 0;  ///< |(Fx/RFx, Fy/RFy)| + |Mz|/RMz
  std::uint32_t fz_mxy = 0;  ///< |Fz|/RFz + |(Mx/RMx, My/RMy)|
};

/// The combined-load rule of commercial F/T sensors: the shear-type loads (Fx, Fy and Mz) share one
/// capacity, the bending-type loads (Fz, Mx, My) another; the sensor is overloaded when either sum
/// of shares exceeds 105 %. Each share is the component (or the Euclidean norm of the in-plane
/// pair, each normalised by its own rating) divided by its rating. Integer arithmetic only:
/// |w| is clamped to 8× rated (certainly overloaded), multiplied by floor(2^48 / rated) and
/// shifted to Q24, so every product stays below 2^51.
class OverloadMonitor {
 public:
  /// Sets the rated range per axis, LSB (1 … kMaxRatedLsb each). False (and unchanged) otherwise.
  [[nodiscard]] bool Configure(const WrenchLsb& rated_lsb);
  [[nodiscard]] bool configured() const { return configured_; }

  /// The two load shares of `w` (sensor frame, LSB). Zero shares before Configure.
  [[nodiscard]] LoadShares Shares(const WrenchLsb& w) const;

  /// Evaluates one sample of the load on the body (sensor frame, untared): updates the peaks and,
  /// on a transition into overload, the event counter. An event starts when either share exceeds
  /// 105 % (or `saturated`: a bridge at its rail under load is overload evidence by itself) and
  /// ends when both shares are back at or below 100 % without saturation. Returns true while
  /// overloaded.
  bool Update(const WrenchLsb& w, bool saturated = false);

  /// Clears the event counter and the peaks (Modbus command 3).
  void Clear();

  [[nodiscard]] std::uint32_t events() const { return events_; }
  /// Largest |component| seen since the last Clear, LSB (|INT32_MIN| reads as INT32_MAX).
  [[nodiscard]] const WrenchLsb& peaks() const { return peaks_; }
  [[nodiscard]] bool overloaded() const { return overloaded_; }

 private:
  [[nodiscard]] std::uint32_t ShareQ24(std::int32_t v, std::size_t axis) const;

  std::array<std::uint64_t, kAxes> recip_{};  ///< floor(2^48 / rated)
  std::array<std::int64_t, kAxes> clamp_{};   ///< 8 × rated
  bool configured_ = false;
  bool overloaded_ = false;
  std::uint32_t events_ = 0;
  WrenchLsb peaks_{};
};

}  // namespace ftstack::fw
