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

}  // namespace ftstack::fw
