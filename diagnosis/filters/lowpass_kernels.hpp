// Math kernels of the exact low passes (first_order.cpp, second_order.cpp), written for vectorized
// loops.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

/// With GCC on x86-64 the filters are compiled twice, for the baseline (SSE2) and for AVX2, and the
/// loader picks one (function multiversioning): AVX2 doubles the width of the coefficient loops.
/// "avx2" does not include FMA, so both versions round alike and give bit-identical results.
/// (Clang does not combine target_clones with the filters' flatten attribute. Not under
/// ThreadSanitizer: its runtime is not ready when the loader runs the ifunc resolvers, and the
/// instrumented resolver crashes at start-up.)
#if __x86_64__ && __GNUC__ && !__clang__ && !__SANITIZE_THREAD__  // undefined macros are 0
#define FTSTACK_LOWPASS_TARGETS [[gnu::target_clones("avx2", "default")]]
#else
#define FTSTACK_LOWPASS_TARGETS
#endif

namespace ftstack::diag::lowpass {

/// Rows whose step coefficients are computed together (a few KiB of buffers, in L1).
inline constexpr std::size_t kChunk = 256;

/// Adding and subtracting 1.5·2^52 rounds a double below 2^51 in magnitude to the nearest integer
/// (with IEEE evaluation, as the build has it: no -ffast-math, which would fold it away).
inline constexpr double kRound = 6755399441055744.0;

/// e^x for |x| ≤ 700 within about an ulp of std::exp, inlined into loops the compiler vectorizes
/// (SSE2 has no vector exp): x = k·ln 2 + r (Cody-Waite with fdlibm's two-part ln 2), the Taylor
/// series of e^r on |r| ≤ ln 2/2 to r^13 (truncation (ln 2/2)^14/14! < 5e-18, Estrin's scheme),
/// then 2^k added to the exponent bits.
inline double ExpKernel(double x) {
  constexpr double kLog2e = 1.4426950408889634074;
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // ln 2 to 32 bits
  constexpr double kLn2Lo = 1.90821492927058770002e-10;  // ln 2 − kLn2Hi
  constexpr double e2 = 1.0 / 2.0, e3 = 1.0 / 6.0, e4 = 1.0 / 24.0, e5 = 1.0 / 120.0;
  constexpr double e6 = 1.0 / 720.0, e7 = 1.0 / 5040.0, e8 = 1.0 / 40320.0, e9 = 1.0 / 362880.0;
  constexpr double e10 = 1.0 / 3628800.0, e11 = 1.0 / 39916800.0, e12 = 1.0 / 479001600.0;
  constexpr double e13 = 1.0 / 6227020800.0;
  const double kd = x * kLog2e + kRound;  // k in its low mantissa bits
  const double k = kd - kRound;
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  const double r2 = r * r;
  const double r4 = r2 * r2;
  const double q = (r + r2 * (e2 + r * e3)) + r4 * ((e4 + r * e5) + r2 * (e6 + r * e7)) +
                   (r4 * r4) * ((e8 + r * e9) + r2 * (e10 + r * e11) + r4 * (e12 + r * e13));
  const double p = 1.0 + q;  // e^r in [0.70, 1.42]: 2^k scales it by its exponent field alone
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(p) +
                               (std::bit_cast<std::uint64_t>(kd) << 52));
}

/// Angles up to which SinCosKernel reduces exactly enough (q·kPio2Hi is exact for q < 2^20).
inline constexpr double kMaxAngle = 1e5;

/// cos θ and sin θ for 0 ≤ θ ≤ kMaxAngle within about an ulp, inlined into loops the compiler
/// vectorizes: θ = q·π/2 + r with q the nearest integer (Cody-Waite with fdlibm's two-part π/2, r
/// exact to ~1e-22), the Taylor series of sin r and cos r on |r| ≤ π/4 (truncation below 5e-17:
/// (π/4)^17/17! and (π/4)^18/18!), then the quadrant q mod 4 picks and signs them.
inline void SinCosKernel(double th, double* co, double* si) {
  constexpr double kTwoOverPi = 0.63661977236758134308;
  constexpr double kPio2Hi = 1.57079632673412561417e+00;  // π/2 to 33 bits
  constexpr double kPio2Lo = 6.07710050650619224932e-11;  // π/2 − kPio2Hi
  // (−1)^k/(2k+1)! and (−1)^k/(2k)!: n! is exact in a double up to 18!.
  constexpr double s3 = -1.0 / 6.0, s5 = 1.0 / 120.0, s7 = -1.0 / 5040.0, s9 = 1.0 / 362880.0;
  constexpr double s11 = -1.0 / 39916800.0, s13 = 1.0 / 6227020800.0;
  constexpr double s15 = -1.0 / 1307674368000.0;
  constexpr double c4 = 1.0 / 24.0, c6 = -1.0 / 720.0, c8 = 1.0 / 40320.0;
  constexpr double c10 = -1.0 / 3628800.0, c12 = 1.0 / 479001600.0;
  constexpr double c14 = -1.0 / 87178291200.0, c16 = 1.0 / 20922789888000.0;
  const double q = (th * kTwoOverPi + kRound) - kRound;
  const double r = (th - q * kPio2Hi) - q * kPio2Lo;
  const double z = r * r;
  const double z2 = z * z;
  const double z4 = z2 * z2;
  const double sr =
      r + (r * z) * ((s3 + z * s5) + z2 * (s7 + z * s9) + z4 * ((s11 + z * s13) + z2 * s15));
  const double cr =
      1.0 +
      (-0.5 * z + z2 * ((c4 + z * c6) + z2 * (c8 + z * c10) + z4 * ((c12 + z * c14) + z2 * c16)));
  // q mod 4 from q/4 minus its floor (q/4 − 0.375 rounds to the floor with no ties).
  const double q4 = 0.25 * q;
  const double quadrant = 4.0 * (q4 - ((q4 - 0.375 + kRound) - kRound));
  const bool odd = quadrant == 1.0 || quadrant == 3.0;
  const double sin_abs = odd ? cr : sr;
  const double cos_abs = odd ? sr : cr;
  *si = quadrant >= 2.0 ? -sin_abs : sin_abs;
  *co = quadrant == 1.0 || quadrant == 2.0 ? -cos_abs : cos_abs;
}

/// Σ c[k]·u^k for k ≤ K by Horner's rule, unrolled at compile time (a loop over k would stay a
/// loop for large K and keep the compiler from vectorizing across rows).
template <int K, std::size_t N>
inline double Horner(const std::array<double, N>& c, double u) {
  static_assert(K >= 0 && K < static_cast<int>(N));
  return [&]<std::size_t... I>(std::index_sequence<I...>) {
    double h = c[K];
    ((h = h * u + c[K - 1 - I]), ...);
    return h;
  }
  (std::make_index_sequence<K>{});
}

/// A flag for "v is outside [lo, hi] or NaN", to be OR-ed over a chunk: the bits of 1.0 or of 0.0,
/// which keeps the loops vectorizable (a bool reduction or && of comparisons would not).
inline std::uint64_t Outside(double v, double lo, double hi) {
  return std::bit_cast<std::uint64_t>(v >= lo ? 0.0 : 1.0) |
         std::bit_cast<std::uint64_t>(v <= hi ? 0.0 : 1.0);
}

/// The time steps dt[j] = t[i0 + j] − t[i0 + j − 1] of a chunk; returns whether they are all equal
/// (bit for bit: an OR of XORs, a reduction the compiler vectorizes).
inline bool ChunkSteps(const double* t_s, std::size_t i0, std::size_t len, double* dt) {
  for (std::size_t j = 0; j < len; ++j) dt[j] = t_s[i0 + j] - t_s[i0 + j - 1];
  const auto first = std::bit_cast<std::uint64_t>(t_s[i0] - t_s[i0 - 1]);
  std::uint64_t differ = 0;
  for (std::size_t j = 0; j < len; ++j) differ |= std::bit_cast<std::uint64_t>(dt[j]) ^ first;
  return differ == 0;
}

/// The smallest and largest of v[0..len) (len ≥ 1), four accumulators in flight as the compiler
/// does not vectorize a min or max of doubles. A NaN is skipped unless it is v[0] (then both are
/// NaN); the series loops give NaN coefficients for a NaN step, as the closed forms do.
inline void StepRange(const double* v, std::size_t len, double* lo, double* hi) {
  double mn[4] = {v[0], v[0], v[0], v[0]};
  double mx[4] = {v[0], v[0], v[0], v[0]};
  std::size_t j = 0;
  for (; j + 4 <= len; j += 4) {
    for (std::size_t q = 0; q < 4; ++q) {
      mn[q] = std::min(mn[q], v[j + q]);
      mx[q] = std::max(mx[q], v[j + q]);
    }
  }
  for (; j < len; ++j) {
    mn[0] = std::min(mn[0], v[j]);
    mx[0] = std::max(mx[0], v[j]);
  }
  *lo = std::min(std::min(mn[0], mn[1]), std::min(mn[2], mn[3]));
  *hi = std::max(std::max(mx[0], mx[1]), std::max(mx[2], mx[3]));
}

}  // namespace ftstack::diag::lowpass
