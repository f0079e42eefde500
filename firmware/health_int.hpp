// Integer helpers shared by the health watch's judgements (per-sample path: no floating point).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ftstack::fw::health_int {

[[nodiscard]] inline std::int64_t Abs(std::int64_t v) { return v < 0 ? -v : v; }

/// log2 of the power of two nearest below `n` (n ≥ 1).
[[nodiscard]] inline std::uint8_t Log2Floor(std::uint32_t n) {
  std::uint8_t k = 0;
  while ((n >> (k + 1)) != 0) ++k;
  return k;
}

[[nodiscard]] inline std::int32_t Sat32(std::int64_t v) {
  return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : static_cast<std::int32_t>(v));
}

[[nodiscard]] inline std::int32_t Median3(const std::array<std::int32_t, 3>& v) {
  const std::int32_t a = v[0], b = v[1], c = v[2];
  if ((a <= b && b <= c) || (c <= b && b <= a)) return b;
  if ((b <= a && a <= c) || (c <= a && a <= b)) return a;
  return c;
}

/// The median of the first `n` (1 ≤ n ≤ N) values (the mean of the middle two for an even n),
/// by insertion sort of a copy: meant for a handful of values.
template <std::size_t N>
[[nodiscard]] std::int64_t Median(std::array<std::int32_t, N> v, std::size_t n) {
  for (std::size_t i = 1; i < n; ++i) {
    const std::int32_t x = v[i];
    std::size_t j = i;
    for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
    v[j] = x;
  }
  return (std::int64_t{v[(n - 1) / 2]} + v[n / 2]) / 2;
}

}  // namespace ftstack::fw::health_int
