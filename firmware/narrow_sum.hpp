// The narrow form's per-sample counts sum (clamp, 32x32->64 products, offset removal): SSE2, NEON
// or scalar.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "hal/adc.hpp"

#ifdef __SSE2__
#include <emmintrin.h>
#elif defined __aarch64__
#include <arm_neon.h>
#endif

namespace ftstack::fw::narrow {

inline constexpr std::size_t kRows = 6;

/// The cached coefficients of the narrow counts sum at one ΔT (WrenchCore::UpdateEffective):
/// coef_u[c][r] = c'_rc + 2^31 (c'_rc = round(eff_rc / 2^k_r), |c'| < 2^31) as 64-bit lanes
/// (SSE2 pmuludq reads their low halves), the same as 32-bit words (NEON umlal), and
/// konst[r] = floor(K_r / 2^k_r) + Σ_c c'_rc·(lo − zero_c) modulo 2^64 with lo the lower rail.
/// With x_u = v − lo (v the counts clamped to the rails, 0 ≤ x_u < 2^32):
///   Σ_c c'·(v − zero) + floor(K/2^k) = konst + Σ_c coef_u·x_u − 2^31·Σ_c x_u   (mod 2^64),
/// exact because the loader bounds the true value (EvaluationFits).
struct Table {
  alignas(16) std::array<std::array<std::uint64_t, kRows>, hal::kMaxChannels> coef_u{};
  alignas(16) std::array<std::array<std::uint32_t, kRows>, hal::kMaxChannels> coef_u32{};
  alignas(16) std::array<std::uint64_t, kRows> konst{};
};

/// Clamps counts[0..N) to [lo, hi] into v and returns whether any had to be; t[r] receives
/// floor(K_r/2^k_r) + Σ_c c'_rc·(v_c − zero_c) modulo 2^64 (see Table).
template <std::size_t N>
[[gnu::always_inline]] inline bool CountsSum(
    const std::array<std::int32_t, hal::kMaxChannels>& counts, std::int32_t lo, std::int32_t hi,
    const Table& tab, std::array<std::int32_t, hal::kMaxChannels>& v,
    std::array<std::uint64_t, kRows>& t) {
  static_assert(N >= 1 && N <= hal::kMaxChannels && hal::kMaxChannels == 8);
#if defined(__SSE2__)
  constexpr std::size_t kVec = (N + 3) / 4;
  const __m128i lo4 = _mm_set1_epi32(lo);
  const __m128i hi4 = _mm_set1_epi32(hi);
  __m128i x[2];  // NOLINT: x_u, four 32-bit lanes each
  int outside = 0;
  for (std::size_t i = 0; i < kVec; ++i) {
    __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(counts.data() + 4 * i));  // NOLINT
    const __m128i above = _mm_cmpgt_epi32(c, hi4);
    const __m128i below = _mm_cmpgt_epi32(lo4, c);
    c = _mm_or_si128(_mm_and_si128(above, hi4), _mm_andnot_si128(above, c));
    c = _mm_or_si128(_mm_and_si128(below, lo4), _mm_andnot_si128(below, c));
    outside |= _mm_movemask_ps(_mm_castsi128_ps(_mm_or_si128(above, below))) << (4 * i);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(v.data() + 4 * i), c);  // NOLINT
    x[i] = _mm_sub_epi32(c, lo4);
  }
  if constexpr (N % 4 != 0) {  // lanes beyond N read as 0 (their coefficients are never used)
    constexpr int k = static_cast<int>(N % 4);
    const __m128i keep = _mm_set_epi32(0, k > 2 ? -1 : 0, k > 1 ? -1 : 0, -1);
    x[kVec - 1] = _mm_and_si128(x[kVec - 1], keep);
  }
  const auto* col = reinterpret_cast<const __m128i*>(tab.coef_u.data());                // NOLINT
  __m128i s0 = _mm_load_si128(reinterpret_cast<const __m128i*>(tab.konst.data()));      // NOLINT
  __m128i s1 = _mm_load_si128(reinterpret_cast<const __m128i*>(tab.konst.data()) + 1);  // NOLINT
  __m128i s2 = _mm_load_si128(reinterpret_cast<const __m128i*>(tab.konst.data()) + 2);  // NOLINT
  auto madd = [&](std::size_t c, __m128i xb) {
    s0 = _mm_add_epi64(s0, _mm_mul_epu32(_mm_load_si128(col + 3 * c), xb));
    s1 = _mm_add_epi64(s1, _mm_mul_epu32(_mm_load_si128(col + 3 * c + 1), xb));
    s2 = _mm_add_epi64(s2, _mm_mul_epu32(_mm_load_si128(col + 3 * c + 2), xb));
  };
  // x_c in lanes 0 and 2 (pmuludq reads the low half of each 64-bit lane): one pshufd each.
  for (std::size_t i = 0; i < kVec; ++i) {
    if (4 * i + 0 < N) madd(4 * i + 0, _mm_shuffle_epi32(x[i], 0x00));
    if (4 * i + 1 < N) madd(4 * i + 1, _mm_shuffle_epi32(x[i], 0x55));
    if (4 * i + 2 < N) madd(4 * i + 2, _mm_shuffle_epi32(x[i], 0xAA));
    if (4 * i + 3 < N) madd(4 * i + 3, _mm_shuffle_epi32(x[i], 0xFF));
  }
  // 2^31·Σ x_u in both 64-bit lanes.
  const __m128i low = _mm_set_epi32(0, -1, 0, -1);
  __m128i sum = _mm_add_epi64(_mm_and_si128(x[0], low), _mm_srli_epi64(x[0], 32));
  if constexpr (kVec > 1) {
    sum = _mm_add_epi64(sum, _mm_add_epi64(_mm_and_si128(x[1], low), _mm_srli_epi64(x[1], 32)));
  }
  sum = _mm_slli_epi64(_mm_add_epi64(sum, _mm_shuffle_epi32(sum, 0x4E)), 31);
  auto* out = reinterpret_cast<__m128i*>(t.data());  // NOLINT
  _mm_storeu_si128(out, _mm_sub_epi64(s0, sum));
  _mm_storeu_si128(out + 1, _mm_sub_epi64(s1, sum));
  _mm_storeu_si128(out + 2, _mm_sub_epi64(s2, sum));
  return (outside & ((1 << N) - 1)) != 0;
#elif defined(__aarch64__)
  bool clamped = false;
  std::array<std::uint32_t, hal::kMaxChannels> xu{};
  std::uint64_t xsum = 0;
  for (std::size_t c = 0; c < N; ++c) {
    const std::int32_t w = counts[c] < lo ? lo : (counts[c] > hi ? hi : counts[c]);
    clamped |= w != counts[c];
    v[c] = w;
    xu[c] = static_cast<std::uint32_t>(w) - static_cast<std::uint32_t>(lo);
    xsum += xu[c];
  }
  uint64x2_t s0 = vld1q_u64(tab.konst.data());
  uint64x2_t s1 = vld1q_u64(tab.konst.data() + 2);
  uint64x2_t s2 = vld1q_u64(tab.konst.data() + 4);
  const uint32x4_t x0 = vld1q_u32(xu.data());
  const uint32x4_t x1 = vld1q_u32(xu.data() + 4);
  auto madd = [&](std::size_t c, uint32x2_t xb) {
    const std::uint32_t* p = tab.coef_u32[c].data();
    s0 = vmlal_u32(s0, vld1_u32(p), xb);  // umlal: two 32x32->64 products added
    s1 = vmlal_u32(s1, vld1_u32(p + 2), xb);
    s2 = vmlal_u32(s2, vld1_u32(p + 4), xb);
  };
  if constexpr (N > 0) madd(0, vdup_laneq_u32(x0, 0));
  if constexpr (N > 1) madd(1, vdup_laneq_u32(x0, 1));
  if constexpr (N > 2) madd(2, vdup_laneq_u32(x0, 2));
  if constexpr (N > 3) madd(3, vdup_laneq_u32(x0, 3));
  if constexpr (N > 4) madd(4, vdup_laneq_u32(x1, 0));
  if constexpr (N > 5) madd(5, vdup_laneq_u32(x1, 1));
  if constexpr (N > 6) madd(6, vdup_laneq_u32(x1, 2));
  if constexpr (N > 7) madd(7, vdup_laneq_u32(x1, 3));
  const uint64x2_t corr = vdupq_n_u64(xsum << 31);
  vst1q_u64(t.data(), vsubq_u64(s0, corr));
  vst1q_u64(t.data() + 2, vsubq_u64(s1, corr));
  vst1q_u64(t.data() + 4, vsubq_u64(s2, corr));
  return clamped;
#else
  bool clamped = false;
  t = tab.konst;
  std::uint64_t xsum = 0;
  for (std::size_t c = 0; c < N; ++c) {
    const std::int32_t w = counts[c] < lo ? lo : (counts[c] > hi ? hi : counts[c]);
    clamped |= w != counts[c];
    v[c] = w;
    const std::uint64_t xu = static_cast<std::uint32_t>(w) - static_cast<std::uint32_t>(lo);
    xsum += xu;
    for (std::size_t r = 0; r < kRows; ++r) t[r] += tab.coef_u[c][r] * xu;
  }
  for (std::size_t r = 0; r < kRows; ++r) t[r] -= xsum << 31;
  return clamped;
#endif
}

/// The last step of the narrow form without second-order features: y_r = floor(T_r / 2^shift_r)
/// for T_r = t_r modulo 2^64 with −2^63 ≤ T_r < 2^63 (the loader bounds the sums). With
/// u = T + 2^63 ≥ 0, floor(u / 2^shift) = floor(T / 2^shift) + 2^(63 − shift) (a logical shift),
/// and offset_r = 2^31 − 2^(63 − shift_r) turns it into y + 2^31, in [0, 2^32) iff y fits int32.
struct Final {
  alignas(16) std::array<std::uint64_t, kRows> shift{};   ///< s_r − k_r ≤ 62
  alignas(16) std::array<std::uint64_t, kRows> offset{};  ///< 2^31 − 2^(63 − shift_r) mod 2^64
};

/// Writes y and returns true when every y_r fits int32; false (y partly written) otherwise.
[[gnu::always_inline]] inline bool ShiftToI32(const std::array<std::uint64_t, kRows>& t,
                                              const Final& f, std::array<std::int32_t, kRows>& y) {
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi64x(std::numeric_limits<long long>::min());  // 2^63
  const auto* tv = reinterpret_cast<const __m128i*>(t.data());                  // NOLINT
  const auto* off = reinterpret_cast<const __m128i*>(f.offset.data());          // NOLINT
  __m128i w[3];  // NOLINT: y_r + 2^31 in each 64-bit lane
  for (std::size_t i = 0; i < 3; ++i) {
    const __m128i u = _mm_add_epi64(_mm_loadu_si128(tv + i), bias);
    // psrlq shifts both lanes by one count: shift twice and keep one lane of each.
    const auto* sh = reinterpret_cast<const __m128i*>(f.shift.data() + 2 * i);  // NOLINT
    const __m128i a = _mm_srl_epi64(u, _mm_loadl_epi64(sh));
    const __m128i b = _mm_srl_epi64(u, _mm_srli_si128(_mm_load_si128(sh), 8));
    const __m128i lanes = _mm_castpd_si128(_mm_move_sd(_mm_castsi128_pd(b), _mm_castsi128_pd(a)));
    w[i] = _mm_add_epi64(lanes, _mm_load_si128(off + i));
  }
  const __m128i any = _mm_or_si128(_mm_or_si128(w[0], w[1]), w[2]);
  const int high_zero = _mm_movemask_epi8(_mm_cmpeq_epi32(any, _mm_setzero_si128()));
  const __m128i flip = _mm_set1_epi32(static_cast<int>(0x80000000u));
  const __m128i y03 = _mm_castps_si128(
      _mm_shuffle_ps(_mm_castsi128_ps(w[0]), _mm_castsi128_ps(w[1]), 0x88));         // low dwords
  _mm_storeu_si128(reinterpret_cast<__m128i*>(y.data()), _mm_xor_si128(y03, flip));  // NOLINT
  _mm_storel_epi64(reinterpret_cast<__m128i*>(y.data() + 4),                         // NOLINT
                   _mm_xor_si128(_mm_shuffle_epi32(w[2], 0x08), flip));
  return (high_zero & 0xF0F0) == 0xF0F0;
#else
  std::uint64_t outside = 0;
  for (std::size_t r = 0; r < kRows; ++r) {
    const std::uint64_t w = ((t[r] + (std::uint64_t{1} << 63)) >> f.shift[r]) + f.offset[r];
    outside |= w;
    y[r] = static_cast<std::int32_t>(static_cast<std::uint32_t>(w) ^ 0x80000000u);
  }
  return (outside >> 32) == 0;
#endif
}

/// Six unsigned 64-bit sums of 32x32-bit products (the low halves of col's lanes times x < 2^32):
/// the second-order features' group of the narrow form.
class Sums6 {
 public:
#if defined(__SSE2__)
  void Add(const std::array<std::uint64_t, kRows>& col, std::uint64_t x) {
    const __m128i xb = _mm_set1_epi64x(static_cast<long long>(x));
    const auto* p = reinterpret_cast<const __m128i*>(col.data());  // NOLINT
    s_[0] = _mm_add_epi64(s_[0], _mm_mul_epu32(_mm_loadu_si128(p), xb));
    s_[1] = _mm_add_epi64(s_[1], _mm_mul_epu32(_mm_loadu_si128(p + 1), xb));
    s_[2] = _mm_add_epi64(s_[2], _mm_mul_epu32(_mm_loadu_si128(p + 2), xb));
  }
  void Store(std::array<std::uint64_t, kRows>& out) const {
    auto* o = reinterpret_cast<__m128i*>(out.data());  // NOLINT
    for (std::size_t i = 0; i < 3; ++i) _mm_storeu_si128(o + i, s_[i]);
  }

 private:
  __m128i s_[3] = {};  // NOLINT: vector registers (std::array drops their attributes)
#else
  void Add(const std::array<std::uint64_t, kRows>& col, std::uint64_t x) {
    for (std::size_t r = 0; r < kRows; ++r) s_[r] += (col[r] & 0xFFFFFFFFu) * x;
  }
  void Store(std::array<std::uint64_t, kRows>& out) const { out = s_; }

 private:
  std::array<std::uint64_t, kRows> s_{};
#endif
};

/// CountsSum for a run-time channel count 1 … kMaxChannels (a switch over the instances).
[[gnu::always_inline]] inline bool CountsSumN(
    std::size_t n, const std::array<std::int32_t, hal::kMaxChannels>& counts, std::int32_t lo,
    std::int32_t hi, const Table& tab, std::array<std::int32_t, hal::kMaxChannels>& v,
    std::array<std::uint64_t, kRows>& t) {
  switch (n) {
    case 1:
      return CountsSum<1>(counts, lo, hi, tab, v, t);
    case 2:
      return CountsSum<2>(counts, lo, hi, tab, v, t);
    case 3:
      return CountsSum<3>(counts, lo, hi, tab, v, t);
    case 4:
      return CountsSum<4>(counts, lo, hi, tab, v, t);
    case 5:
      return CountsSum<5>(counts, lo, hi, tab, v, t);
    case 6:
      return CountsSum<6>(counts, lo, hi, tab, v, t);
    case 7:
      return CountsSum<7>(counts, lo, hi, tab, v, t);
    default:
      return CountsSum<8>(counts, lo, hi, tab, v, t);
  }
}

}  // namespace ftstack::fw::narrow
