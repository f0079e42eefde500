// Saturating integer helpers for the fixed-point core: clamps that report when they clamped.
#pragma once

#include <cstdint>
#include <limits>

namespace ftstack::fw {

/// Clamps a 64-bit value into int32; sets *saturated when it had to clamp.
[[nodiscard]] constexpr std::int32_t SatToI32(std::int64_t v, bool* saturated) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int32_t>::max();
  constexpr std::int64_t kMin = std::numeric_limits<std::int32_t>::min();
  if (v > kMax) {
    *saturated = true;
    return static_cast<std::int32_t>(kMax);
  }
  if (v < kMin) {
    *saturated = true;
    return static_cast<std::int32_t>(kMin);
  }
  return static_cast<std::int32_t>(v);
}

/// a + b in int32 with saturation.
[[nodiscard]] constexpr std::int32_t SatAdd32(std::int32_t a, std::int32_t b, bool* saturated) {
  return SatToI32(static_cast<std::int64_t>(a) + b, saturated);
}

/// a - b in int32 with saturation.
[[nodiscard]] constexpr std::int32_t SatSub32(std::int32_t a, std::int32_t b, bool* saturated) {
  return SatToI32(static_cast<std::int64_t>(a) - b, saturated);
}

/// Rounds v / 2^shift to nearest (ties toward +inf); shift 0 … 62. Arithmetic shift (C++20).
[[nodiscard]] constexpr std::int64_t RoundShift(std::int64_t v, unsigned shift) {
  if (shift == 0) return v;
  const std::int64_t half = std::int64_t{1} << (shift - 1);
  // v + half cannot overflow for |v| < 2^62, which the loader guarantees.
  return (v + half) >> shift;
}

/// Rounds a / b to nearest for b > 0 (ties away from zero).
[[nodiscard]] constexpr std::int64_t RoundDiv(std::int64_t a, std::int64_t b) {
  return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b);
}

/// ceil(2^63 / d) for 1 ≤ d ≤ 2^16: the reciprocal RoundDivByReciprocal multiplies with.
[[nodiscard]] constexpr std::uint64_t Reciprocal63(std::uint32_t d) {
  return ((std::uint64_t{1} << 63) + d - 1) / d;
}

/// RoundDiv(a, d) without a division, for 1 ≤ d ≤ 2^16, |a| < 2^46 and m = Reciprocal63(d).
/// Exact: write m = (2^63 + e) / d with 0 ≤ e < d, and u = |a| + ⌊d/2⌋ = q·d + ρ, 0 ≤ ρ < d.
/// Then u·m / 2^63 = q + ρ/d + u·e / (d·2^63), and u·e < (2^46 + 2^15)·2^16 < 2^63, so the
/// fraction stays below (ρ + 1)/d ≤ 1 and ⌊u·m / 2^63⌋ = q = ⌊u / d⌋, as RoundDiv computes.
[[nodiscard]] constexpr std::int64_t RoundDivByReciprocal(std::int64_t a, std::uint32_t d,
                                                          std::uint64_t m) {
  const std::uint64_t mag =
      a >= 0 ? static_cast<std::uint64_t>(a) : 0 - static_cast<std::uint64_t>(a);
  const std::uint64_t u = mag + d / 2;
#if defined(__SIZEOF_INT128__)
  __extension__ typedef unsigned __int128 Uint128;
  const auto q = static_cast<std::uint64_t>((static_cast<Uint128>(u) * m) >> 63);
#else
  (void)m;
  const std::uint64_t q = u / d;  // targets without a 64×64→128 multiply divide instead
#endif
  return a >= 0 ? static_cast<std::int64_t>(q) : -static_cast<std::int64_t>(q);
}

}  // namespace ftstack::fw
