// Gravity compensation: subtracts a payload's weight, its moment and the sensor bias per sample.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"

namespace ftstack::fw {

/// Largest accepted payload mass, kg, and |m·c| per axis, kg·m (keeps every product below 2^62).
inline constexpr double kMaxPayloadMassKg = 100.0;
inline constexpr double kMaxPayloadFirstMomentKgM = 100.0;
/// Largest accepted |gravity| component, m/s² (holding registers 22–27), and its integer form.
inline constexpr double kMaxGravityMps2 = 20.0;
inline constexpr std::int32_t kMaxGravityUmps2 = 20'000'000;

/// A payload in integers: the reading of a static sensor carrying it is
///   F = m·g + F_b,   M = (m·c) × g + M_b   (sensor frame)
/// mass in µg (1e-9 kg), first moment m·c in µg·m (1e-9 kg·m), gravity in µm/s² (1e-6 m/s²):
/// m·g is then in 1e-15 N and (m·c) × g in 1e-15 N·m; |m| ≤ 1e11 µg, |m·c| ≤ 1e11 µg·m and
/// |g| ≤ 2e7 µm/s² keep each product ≤ 2e18 and each cross-product difference ≤ 4e18 < 2^62.
struct FixedPayload {
  std::int64_t mass_ug = 0;
  std::array<std::int64_t, 3> first_moment_ug_m{};
  WrenchLsb bias_lsb{};  ///< F_b in mN, M_b in 10 µN·m
  bool present = false;
};

enum class PayloadStatus : std::uint8_t {
  kOk = 0,
  kNotFinite,   ///< a NaN or infinity
  kOutOfRange,  ///< mass ≤ 0 or above kMaxPayloadMassKg, |m·c| or a bias out of range
};

/// Builds the integer form (floating point, at start-up only). On refusal *out is untouched.
[[nodiscard]] PayloadStatus MakeFixedPayload(double mass_kg, const std::array<double, 3>& com_m,
                                             const std::array<double, 3>& force_bias_n,
                                             const std::array<double, 3>& moment_bias_nm,
                                             FixedPayload* out);

/// Converts a gravity component (m/s², from a holding register; configuration time) to µm/s².
/// False for NaN, infinity or |g| > kMaxGravityMps2.
[[nodiscard]] bool GravityToFixed(float g_mps2, std::int32_t* out_umps2);

/// out = in − (m·g + F_b, (m·c) × g + M_b), integer only, rounded to nearest LSB. Error against
/// exact arithmetic on the registers' values: ≤ 1 LSB (rounding of the result and of the bias)
/// plus the gravity's quantisation to µm/s², i.e. ≤ |m·c|·1e-6 N·m per moment component (0.1 LSB
/// at 1 kg·m) and ≤ m·1e-6 N per force component (≪ 1 mN). Sets
/// *saturated if an axis was clamped to int32. `gravity_umps2` must be within ±kMaxGravityUmps2.
void CompensateGravity(const FixedPayload& p, const std::array<std::int32_t, 3>& gravity_umps2,
                       const WrenchLsb& in, WrenchLsb* out, bool* saturated);

}  // namespace ftstack::fw
