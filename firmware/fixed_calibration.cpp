#include "firmware/fixed_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ftstack::fw {

const char* ToString(LoadStatus s) {
  switch (s) {
    case LoadStatus::kOk:
      return "ok";
    case LoadStatus::kBadChannelCount:
      return "channel count outside 1..8 or different from the ADC's";
    case LoadStatus::kNotFinite:
      return "calibration contains NaN or infinity";
    case LoadStatus::kBadAdcScaling:
      return "ADC scaling unusable (full scale or rails)";
    case LoadStatus::kOutputOverflow:
      return "worst-case output overflows int32 (matrix too large for the ADC range)";
    case LoadStatus::kBadTerms:
      return "second-order term or temperature range unusable";
    case LoadStatus::kFeatureOverflow:
      return "a second-order feature's product could pass 2^63 (ADC rails too wide)";
  }
  return "unknown";
}

double CountsPerMvv(const hal::AdcInfo& adc) {
  // Rails may both be ≥ 0 (a unipolar converter: codes 0 … 2^B − 1 with zero input at 0).
  if (adc.full_scale_nvv <= 0 || adc.max_counts <= 0 || adc.min_counts >= adc.max_counts) {
    return 0.0;
  }
  return static_cast<double>(adc.max_counts) / (static_cast<double>(adc.full_scale_nvv) * 1e-6);
}

namespace {

constexpr double kInt32Max = static_cast<double>(std::numeric_limits<std::int32_t>::max());
constexpr std::uint64_t kAccLimit = std::uint64_t{1} << 61;

/// Right shift that brings |product| ≤ bound below 2^26 (balances the rounding of the product
/// against the rounding of its coefficient in a 64-bit accumulator).
std::uint8_t ProductShift(double bound) {
  int s = static_cast<int>(std::ceil(std::log2(bound + 1.0))) - 26;
  if (s < 0) s = 0;
  if (s > 62) s = 62;
  return static_cast<std::uint8_t>(s);
}

/// Exact check with integers: Σ |coef_k| · f_k + |bias| ≤ 2^61 (no wrap-around anywhere).
bool AccumulatorFits(const std::array<std::int64_t, kMaxFeatures>& coef, std::int64_t bias,
                     const std::array<std::uint64_t, kMaxFeatures>& fmax, std::size_t count) {
  std::uint64_t total = static_cast<std::uint64_t>(bias < 0 ? -bias : bias);
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint64_t mag = static_cast<std::uint64_t>(coef[k] < 0 ? -coef[k] : coef[k]);
    std::uint64_t term = 0;
    if (__builtin_mul_overflow(mag, fmax[k], &term)) return false;
    if (__builtin_add_overflow(total, term, &total)) return false;
  }
  return total <= kAccLimit;
}

/// Exact check with integers that the core's raw product of a second-order feature cannot leave
/// int64: |a|·|b| + 2^(shift−1) (RoundShift's half) ≤ 2^63 − 1 for |a| ≤ amax, |b| ≤ bmax.
bool RawProductFits(std::uint64_t amax, std::uint64_t bmax, std::uint8_t shift) {
  std::uint64_t p = 0;
  if (__builtin_mul_overflow(amax, bmax, &p)) return false;
  const std::uint64_t half = shift > 0 ? std::uint64_t{1} << (shift - 1) : 0;
  if (__builtin_add_overflow(p, half, &p)) return false;
  return p <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
}

std::uint64_t Mag(std::int64_t v) {
  return v < 0 ? 0 - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
}

/// D_c = ⌊|C_c|·ΔT_max / 2^h_c⌋ + 1 ≥ |round(C_c·ΔT / 2^h_c)| for the ΔT product of channel c
/// (0 without one); false when C_c·ΔT plus its rounding half could leave int64.
bool DriftBounds(const std::array<std::int64_t, kMaxFeatures>& coef, const FixedCalibration& fixed,
                 std::uint64_t dt_max, std::array<std::uint64_t, kMaxChannels>* drift) {
  *drift = {};
  for (std::size_t k = 0; k < fixed.extra_count; ++k) {
    const FixedFeature& e = fixed.extra[k];
    if (e.kind != FeatureKind::kTempProduct) continue;
    const std::uint64_t q = Mag(coef[fixed.channel_count + k]);
    std::uint64_t p = 0;
    if (__builtin_mul_overflow(q, dt_max, &p) || !RawProductFits(q, dt_max, e.shift)) return false;
    (*drift)[e.a] = (p >> e.shift) + 1;
  }
  return true;
}

/// One-sided bound on a product feature round(x̃_a·x̃_b / 2^shift) (RawProductFits holds).
std::uint64_t ProductBound(const FixedFeature& e,
                           const std::array<std::uint64_t, kMaxChannels>& xmax) {
  return ((xmax[e.a] * xmax[e.b]) >> e.shift) + 1;
}

/// Exact check with integers for the core's evaluation order (WrenchCore): per sample it sums
///   K + Σ_c (coef_c + d_c(ΔT))·x̃_c + Σ_k q_k·p_k,  K = bias + Σ_c coef_c·zero_c + coef_ΔT·ΔT,
/// x̃_c = counts_c − zero_c, with d_c(ΔT) = round(C_c·ΔT / 2^h_c) (C_c, h_c: the ΔT-product
/// feature of channel c) computed once per temperature, and subtracts the same sum at the tare.
/// Proves |C_c|·ΔT_max + 2^(h_c−1) ≤ 2^63 − 1 (no wrap in d_c) and U = |bias| + |coef_ΔT|·ΔT_max
/// + Σ_c (|coef_c|·|zero_c| + (|coef_c| + D_c + slack)·x_max,c) + Σ_k (|q_k| + slack_p)·p_max,k
/// ≤ 2^61 (DriftBounds): every partial sum of one evaluation is then ≤ U, a tared one (minus the
/// tare's sum) ≤ 2U ≤ 2^62, and adding the final rounding half (≤ 2^61) stays below 2^63. `slack`
/// covers the narrow form's coefficients (NarrowRow), off by up to 2^(k−1) from these.
bool EvaluationFits(const std::array<std::int64_t, kMaxFeatures>& coef, std::int64_t bias,
                    const FixedCalibration& fixed,
                    const std::array<std::uint64_t, kMaxChannels>& xmax, std::uint64_t dt_max,
                    std::uint64_t slack, std::uint64_t product_slack) {
  const std::size_t n = fixed.channel_count;
  std::array<std::uint64_t, kMaxChannels> drift{};
  if (!DriftBounds(coef, fixed, dt_max, &drift)) return false;
  std::uint64_t total = Mag(bias);
  bool ok = true;
  auto add = [&](std::uint64_t a, std::uint64_t a2, std::uint64_t b) {
    std::uint64_t t = 0;
    ok = ok && !__builtin_add_overflow(a, a2, &a) && !__builtin_mul_overflow(a, b, &t) &&
         !__builtin_add_overflow(total, t, &total);
  };
  for (std::size_t k = 0; k < fixed.extra_count; ++k) {
    const FixedFeature& e = fixed.extra[k];
    if (e.kind == FeatureKind::kTemperature) add(Mag(coef[n + k]), 0, dt_max);
    if (e.kind == FeatureKind::kProduct) {
      add(Mag(coef[n + k]), product_slack, ProductBound(e, xmax));
    }
  }
  for (std::size_t c = 0; c < n; ++c) {
    std::uint64_t e = 0;
    ok = ok && !__builtin_add_overflow(Mag(coef[c]), drift[c], &e);
    add(e, slack, xmax[c]);
    add(Mag(coef[c]), 0, Mag(fixed.zero[c]));
  }
  return ok && total <= kAccLimit;
}

/// Smallest k with (c_max + 2^(k−1)) / 2^k ≤ 2^31 − 1: the narrow coefficients' right shift.
std::uint8_t NarrowShift(std::uint64_t cmax) {
  constexpr std::uint64_t kMax32 = (std::uint64_t{1} << 31) - 1;
  std::uint8_t k = 0;
  while (k < 62 && ((cmax + (k > 0 ? std::uint64_t{1} << (k - 1) : 0)) >> k) > kMax32) ++k;
  return k;
}

/// The narrow form of row r (the core's SIMD path): 32-bit coefficients round(c / 2^k) for the
/// counts (k = k_c; at every ΔT: |coef_c + d_c| ≤ |coef_c| + D_c) and for the products (k = k_p),
/// features x̃ and p within ±(2^31 − 1), multiplied into two 64-bit sums that the core scales
/// back by 2^k_c and 2^k_p. Picks the smallest shifts; refuses (false) when a feature is too
/// wide, the bound with slack 2^(k−1) fails, or the added error Σ 2^(k−1)/2^s · f_max (twice with
/// a tare) exceeds kNarrowErrorLsb.
constexpr double kNarrowErrorLsb = 1.0 / 16.0;
bool NarrowRow(const FixedCalibration& fixed, std::size_t r,
               const std::array<std::uint64_t, kMaxChannels>& xmax, std::uint64_t dt_max,
               std::array<std::uint8_t, 2>* k_out, double* err_out) {
  constexpr std::uint64_t kMax32 = (std::uint64_t{1} << 31) - 1;
  const std::size_t n = fixed.channel_count;
  std::array<std::uint64_t, kMaxChannels> drift{};
  if (!DriftBounds(fixed.coef[r], fixed, dt_max, &drift)) return false;
  std::array<std::uint64_t, 2> cmax{};  // largest coefficient magnitude: counts, products
  std::array<double, 2> fsum{};         // Σ of the features' one-sided bounds
  for (std::size_t c = 0; c < n; ++c) {
    if (xmax[c] > kMax32) return false;
    cmax[0] = std::max(cmax[0], Mag(fixed.coef[r][c]) + drift[c]);
    fsum[0] += static_cast<double>(xmax[c]);
  }
  for (std::size_t k = 0; k < fixed.extra_count; ++k) {
    const FixedFeature& e = fixed.extra[k];
    if (e.kind != FeatureKind::kProduct) continue;
    if (ProductBound(e, xmax) > kMax32) return false;
    cmax[1] = std::max(cmax[1], Mag(fixed.coef[r][n + k]));
    fsum[1] += static_cast<double>(ProductBound(e, xmax));
  }
  std::array<std::uint64_t, 2> slack{};
  double err = 0.0;
  for (std::size_t g = 0; g < 2; ++g) {
    (*k_out)[g] = NarrowShift(cmax[g]);
    slack[g] = (*k_out)[g] > 0 ? std::uint64_t{1} << ((*k_out)[g] - 1) : 0;
    err += 2.0 * std::ldexp(static_cast<double>(slack[g]), -fixed.shift[r]) * fsum[g];
  }
  if (err > kNarrowErrorLsb ||
      !EvaluationFits(fixed.coef[r], fixed.bias[r], fixed, xmax, dt_max, slack[0], slack[1])) {
    return false;
  }
  *err_out = err;
  return true;
}

/// Stage 1: refuses a calibration the fixed-point form cannot represent (counts, NaN, terms).
[[nodiscard]] LoadStatus CheckInputs(const FloatCalibration& cal, const hal::AdcInfo& adc) {
  const std::size_t n = cal.channel_count;
  if (n < 1 || n > kMaxChannels || (adc.channel_count != 0 && adc.channel_count != n)) {
    return LoadStatus::kBadChannelCount;
  }
  const double counts_per_mvv = CountsPerMvv(adc);
  if (!(counts_per_mvv > 0) || !std::isfinite(counts_per_mvv)) return LoadStatus::kBadAdcScaling;
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (!std::isfinite(cal.bias[r])) return LoadStatus::kNotFinite;
    for (std::size_t c = 0; c < n; ++c) {
      if (!std::isfinite(cal.matrix[r][c]) || !std::isfinite(cal.offset_mvv[c])) {
        return LoadStatus::kNotFinite;
      }
    }
  }
  if (cal.product_count > kMaxProducts) return LoadStatus::kBadTerms;
  for (std::size_t k = 0; k < cal.product_count; ++k) {
    const ProductTerm& t = cal.products[k];
    if (t.a > t.b || t.b >= n) return LoadStatus::kBadTerms;
    for (std::size_t r = 0; r < kAxes; ++r) {
      if (!std::isfinite(cal.product_matrix[r][k])) return LoadStatus::kNotFinite;
    }
  }
  if (cal.temperature_compensated) {
    if (!std::isfinite(cal.temp_ref_c) || !std::isfinite(cal.temp_min_c) ||
        !std::isfinite(cal.temp_max_c)) {
      return LoadStatus::kNotFinite;
    }
    if (!(cal.temp_min_c <= cal.temp_ref_c && cal.temp_ref_c <= cal.temp_max_c) ||
        cal.temp_min_c < -1000.0 || cal.temp_max_c > 1000.0) {
      return LoadStatus::kBadTerms;
    }
    for (std::size_t c = 0; c < n; ++c) {
      if (!std::isfinite(cal.bias_slope_mvv_per_c[c]) || !std::isfinite(cal.gain_slope_per_c[c])) {
        return LoadStatus::kNotFinite;
      }
    }
  }
  return LoadStatus::kOk;
}

/// The feature layout of a calibration and the bounds the overflow proof uses.
struct FeatureLayout {
  double counts_per_mvv = 0;
  std::array<double, kMaxChannels> offset_counts{};
  std::array<double, kMaxChannels> e{};                // zero_c − offset_c, counts
  std::array<double, kMaxChannels> xmax{};             // bound on |counts − zero|
  std::array<std::uint64_t, kMaxChannels> xmax_int{};  // the same, exact
  double dt_max = 0.0;                                 // bound on |ΔT|, m°C
  double dt_ref_err = 0.0;                             // integer reference − true reference, m°C
  std::size_t count = 0;                               // features in use
  std::array<double, kMaxFeatures> fbound{};
  std::array<std::uint64_t, kMaxFeatures> fmax_int{};
  std::size_t temp_index = 0;
  std::array<std::size_t, kMaxProducts> product_index{};
  std::array<std::size_t, kMaxChannels> temp_product_index{};
};

/// Stage 2a: integer zero of the product features and its rounding, the temperature in m°C.
void SetZeroAndTemperature(const FloatCalibration& cal, const hal::AdcInfo& adc,
                           FixedCalibration* fixed, FeatureLayout* lay) {
  const std::size_t n = cal.channel_count;
  const double min_c = adc.min_counts;
  const double max_c = adc.max_counts;
  for (std::size_t c = 0; c < n; ++c) {
    lay->offset_counts[c] = cal.offset_mvv[c] * lay->counts_per_mvv;
    double z = std::nearbyint(lay->offset_counts[c]);
    if (z > max_c) z = max_c;
    if (z < min_c) z = min_c;
    fixed->zero[c] = static_cast<std::int32_t>(z);
    lay->e[c] = z - lay->offset_counts[c];
    lay->xmax[c] = std::fmax(max_c - z, z - min_c);
    const std::int64_t zi = fixed->zero[c];
    lay->xmax_int[c] = static_cast<std::uint64_t>(
        std::max(std::int64_t{adc.max_counts} - zi, zi - std::int64_t{adc.min_counts}));
  }
  if (cal.temperature_compensated) {
    fixed->temperature = true;
    fixed->temp_ref_mdegc = static_cast<std::int32_t>(std::lround(cal.temp_ref_c * 1000.0));
    fixed->temp_min_mdegc = static_cast<std::int32_t>(std::lround(cal.temp_min_c * 1000.0));
    fixed->temp_max_mdegc = static_cast<std::int32_t>(std::lround(cal.temp_max_c * 1000.0));
    lay->dt_max = std::fmax(static_cast<double>(fixed->temp_max_mdegc) - fixed->temp_ref_mdegc,
                            static_cast<double>(fixed->temp_ref_mdegc) - fixed->temp_min_mdegc);
    lay->dt_ref_err = fixed->temp_ref_mdegc - cal.temp_ref_c * 1000.0;
  }
}

/// Stage 2b: feature layout and bounds (f_max with a tare: twice the one-sided bound for derived
/// features).
[[nodiscard]] LoadStatus LayOutFeatures(const FloatCalibration& cal, const hal::AdcInfo& adc,
                                        FixedCalibration* fixed, FeatureLayout* lay) {
  const std::size_t n = cal.channel_count;
  const bool temp = cal.temperature_compensated;
  // Largest |x| = |counts − zero| with counts and zero (a tare or the offset) between the rails.
  const double x_span = static_cast<double>(adc.max_counts) - adc.min_counts;
  std::size_t count = n;
  for (std::size_t c = 0; c < n; ++c) lay->fbound[c] = x_span;
  if (temp) {
    lay->temp_index = count;
    fixed->extra[count - n] = FixedFeature{FeatureKind::kTemperature, 0, 0, 0};
    lay->fbound[count++] = 2.0 * lay->dt_max;
  }
  for (std::size_t k = 0; k < cal.product_count; ++k) {
    const ProductTerm& t = cal.products[k];
    const double bound = lay->xmax[t.a] * lay->xmax[t.b];
    const std::uint8_t sh = ProductShift(bound);
    if (!RawProductFits(lay->xmax_int[t.a], lay->xmax_int[t.b], sh)) {
      return LoadStatus::kFeatureOverflow;
    }
    lay->product_index[k] = count;
    fixed->extra[count - n] = FixedFeature{FeatureKind::kProduct, t.a, t.b, sh};
    lay->fbound[count++] = 2.0 * (std::ceil(std::ldexp(bound, -sh)) + 1.0);
  }
  if (temp) {
    for (std::size_t c = 0; c < n; ++c) {
      if (cal.gain_slope_per_c[c] == 0.0) continue;
      const double bound = lay->xmax[c] * lay->dt_max;
      const std::uint8_t sh = ProductShift(bound);
      if (!RawProductFits(lay->xmax_int[c], static_cast<std::uint64_t>(lay->dt_max), sh)) {
        return LoadStatus::kFeatureOverflow;
      }
      lay->temp_product_index[c] = count;
      fixed->extra[count - n] =
          FixedFeature{FeatureKind::kTempProduct, static_cast<std::uint8_t>(c), 0, sh};
      lay->fbound[count++] = 2.0 * (std::ceil(std::ldexp(bound, -sh)) + 1.0);
    }
  }
  fixed->extra_count = static_cast<std::uint8_t>(count - n);
  lay->count = count;
  for (std::size_t k = 0; k < count; ++k) {
    lay->fmax_int[k] = static_cast<std::uint64_t>(lay->fbound[k]);
  }
  return LoadStatus::kOk;
}

/// One output row in real numbers: coefficients per feature unit and the bias, LSB.
struct RealRow {
  std::array<double, kMaxFeatures> m{};
  double bias_lsb = 0.0;
  double rounding_error = 0.0;  // from rounding the derived features, LSB
};

/// Stage 3: the real coefficients of row r against the integer features.
RealRow MakeRealRow(const FloatCalibration& cal, const FixedCalibration& fixed,
                    const FeatureLayout& lay, std::size_t r) {
  const std::size_t n = cal.channel_count;
  const double lsb = AxisLsb(r);
  const double cpm = lay.counts_per_mvv;
  const auto& e = lay.e;
  RealRow row;
  auto& m = row.m;
  row.bias_lsb = cal.bias[r] / lsb;
  for (std::size_t c = 0; c < n; ++c) {
    m[c] = cal.matrix[r][c] / lsb / cpm;
    row.bias_lsb -= m[c] * lay.offset_counts[c];
  }
  // Products: q·(x̃_a + e_a)(x̃_b + e_b) with x̃ = counts − zero, expanded exactly.
  for (std::size_t k = 0; k < cal.product_count; ++k) {
    const ProductTerm& t = cal.products[k];
    const double q = cal.product_matrix[r][k] / lsb / (cpm * cpm);
    const FixedFeature& f = fixed.extra[lay.product_index[k] - n];
    m[lay.product_index[k]] = q * std::ldexp(1.0, f.shift);
    m[t.a] += q * e[t.b];
    m[t.b] += q * e[t.a];
    row.bias_lsb += q * (e[t.a] * e[t.b] - e[t.b] * fixed.zero[t.a] - e[t.a] * fixed.zero[t.b]);
    if (f.shift > 0) row.rounding_error += 2.0 * 0.5 * std::fabs(m[lay.product_index[k]]);
  }
  // Temperature: −ΔT·(M·α)_r − ΔT·Σ_c M_rc γ_c (x̃_c + e_c), ΔT in m°C against the integer
  // reference (the reference's rounding folds into the constant and linear terms).
  if (cal.temperature_compensated) {
    const double dt_ref_err = lay.dt_ref_err;
    double a_r = 0.0;  // LSB per m°C
    for (std::size_t c = 0; c < n; ++c) {
      a_r -= cal.matrix[r][c] / lsb * cal.bias_slope_mvv_per_c[c] / 1000.0;
    }
    for (std::size_t c = 0; c < n; ++c) {
      if (cal.gain_slope_per_c[c] == 0.0) continue;
      const double g = -(cal.matrix[r][c] / lsb / cpm) * cal.gain_slope_per_c[c] / 1000.0;
      const FixedFeature& f = fixed.extra[lay.temp_product_index[c] - n];
      m[lay.temp_product_index[c]] = g * std::ldexp(1.0, f.shift);
      a_r += g * e[c];
      // ΔT_true = ΔT_int + dt_ref_err: the product's share is linear in x̃_c.
      m[c] += g * dt_ref_err;
      row.bias_lsb -= g * dt_ref_err * fixed.zero[c];
      // The core rounds C·ΔT / 2^shift (once per temperature), not this feature: QuantiseRow adds
      // that rounding once s is known.
    }
    m[lay.temp_index] = a_r;
    row.bias_lsb += a_r * dt_ref_err;
  }
  return row;
}

/// Stage 4: row r in integers with the largest binary point that provably cannot overflow.
[[nodiscard]] LoadStatus QuantiseRow(const RealRow& row, const FeatureLayout& lay, std::size_t r,
                                     FixedCalibration* fixed, LoadReport* rep) {
  const double lsb = AxisLsb(r);
  // Bound on |output| for every input between the rails, with or without a tare (every
  // feature then relative to its value at the tare): Σ |m_k|·f_max,k + |bias|.
  double real_bound = std::fabs(row.bias_lsb);
  double fsum = 1.0;
  for (std::size_t k = 0; k < lay.count; ++k) {
    real_bound += std::fabs(row.m[k]) * lay.fbound[k];
    fsum += lay.fbound[k];
  }
  rep->worst_case_output_lsb[r] = real_bound;
  if (!std::isfinite(real_bound) || real_bound + row.rounding_error + 1.0 > kInt32Max) {
    rep->failing_axis = static_cast<std::uint8_t>(r);
    return LoadStatus::kOutputOverflow;
  }
  // Largest binary point with real_bound·2^s + rounding of the coefficients ≤ 2^61: every
  // partial sum then stays inside ±2^62 and adding the rounding half cannot overflow. Proven
  // again below with exact integer arithmetic.
  const double room = std::ldexp(1.0, 61) - 0.5 * fsum - 1.0;
  int s = real_bound > 0 ? static_cast<int>(std::floor(std::log2(room / real_bound))) : 62;
  if (s > 62) s = 62;
  if (s < 0) s = 0;
  for (;; --s) {
    const double scale = std::ldexp(1.0, s);
    for (std::size_t k = 0; k < lay.count; ++k) fixed->coef[r][k] = std::llround(row.m[k] * scale);
    fixed->bias[r] = std::llround(row.bias_lsb * scale);
    if (AccumulatorFits(fixed->coef[r], fixed->bias[r], lay.fmax_int, lay.count) &&
        EvaluationFits(fixed->coef[r], fixed->bias[r], *fixed, lay.xmax_int,
                       static_cast<std::uint64_t>(lay.dt_max), 0, 0)) {
      break;
    }
    if (s == 0) {
      rep->failing_axis = static_cast<std::uint8_t>(r);
      return LoadStatus::kOutputOverflow;
    }
  }
  fixed->shift[r] = static_cast<std::uint8_t>(s);
  const double scale = std::ldexp(1.0, s);
  // Each coefficient and the bias are off by at most half a unit of 2^-s; derived features
  // are rounded to ±1/2 (twice with a tare); the core's per-temperature drift coefficients
  // round(C_c·ΔT / 2^h) are off by ≤ 1/2 unit of 2^-s per count of |counts − zero| ≤ x_max,c
  // (twice with a tare); the final rounding adds half an LSB.
  double drift_rounding = 0.0;
  for (std::size_t k = 0; k < fixed->extra_count; ++k) {
    const FixedFeature& e = fixed->extra[k];
    if (e.kind == FeatureKind::kTempProduct && e.shift > 0) {
      drift_rounding += 2.0 * 0.5 * lay.xmax[e.a] / scale;
    }
  }
  if (real_bound + row.rounding_error + drift_rounding + 1.0 > kInt32Max) {
    rep->failing_axis = static_cast<std::uint8_t>(r);
    return LoadStatus::kOutputOverflow;
  }
  const double err = 0.5 / scale * fsum + row.rounding_error + drift_rounding + 0.5;
  rep->worst_case_error_lsb[r] = err;
  rep->worst_case_error_si[r] = err * lsb;
  return LoadStatus::kOk;
}

}  // namespace

LoadStatus LoadCalibration(const FloatCalibration& cal, const hal::AdcInfo& adc,
                           FixedCalibration* out, LoadReport* report) {
  LoadReport rep{};
  auto finish = [&](LoadStatus s) {
    rep.status = s;
    if (report != nullptr) *report = rep;
    return s;
  };
  const LoadStatus checked = CheckInputs(cal, adc);
  if (checked != LoadStatus::kOk) return finish(checked);
  FixedCalibration fixed{};
  fixed.channel_count = cal.channel_count;
  fixed.min_counts = adc.min_counts;
  fixed.max_counts = adc.max_counts;
  FeatureLayout lay;
  lay.counts_per_mvv = CountsPerMvv(adc);
  SetZeroAndTemperature(cal, adc, &fixed, &lay);
  const LoadStatus laid = LayOutFeatures(cal, adc, &fixed, &lay);
  if (laid != LoadStatus::kOk) return finish(laid);
  for (std::size_t r = 0; r < kAxes; ++r) {
    const LoadStatus row = QuantiseRow(MakeRealRow(cal, fixed, lay, r), lay, r, &fixed, &rep);
    if (row != LoadStatus::kOk) return finish(row);
  }
  // The narrow (32-bit coefficient) form when every row has one within kNarrowErrorLsb that
  // keeps the row's bound within 1 LSB.
  std::array<double, kAxes> narrow_err{};
  fixed.narrow = true;
  for (std::size_t r = 0; r < kAxes && fixed.narrow; ++r) {
    std::array<std::uint8_t, 2> k{};
    fixed.narrow = NarrowRow(fixed, r, lay.xmax_int, static_cast<std::uint64_t>(lay.dt_max), &k,
                             &narrow_err[r]) &&
                   rep.worst_case_error_lsb[r] + narrow_err[r] <= 1.0;  // never past 1 LSB
    fixed.narrow_shift[r] = k[0];
    fixed.narrow_product_shift[r] = k[1];
  }
  if (!fixed.narrow) {
    fixed.narrow_shift = {};
    fixed.narrow_product_shift = {};
  } else {
    for (std::size_t r = 0; r < kAxes; ++r) {
      rep.worst_case_error_lsb[r] += narrow_err[r];
      rep.worst_case_error_si[r] = rep.worst_case_error_lsb[r] * AxisLsb(r);
    }
  }
  fixed.invalid_axes = static_cast<std::uint8_t>(cal.invalid_axes & ((1u << kAxes) - 1));
  fixed.valid = true;
  *out = fixed;
  return finish(LoadStatus::kOk);
}

}  // namespace ftstack::fw
