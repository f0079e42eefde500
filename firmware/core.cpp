#include "firmware/core.hpp"

#include "firmware/fixed_point.hpp"

#include <algorithm>
#include <limits>

namespace ftstack::fw {

namespace {

/// 2^31: the offset that makes a signed 32-bit value an unsigned one (narrow form).
constexpr std::int64_t kHalf32 = std::int64_t{1} << 31;

/// Reciprocals of every moving-average fill 1 … kMaxFilterLength (index 0 unused).
constexpr auto kFillReciprocal = [] {
  std::array<std::uint64_t, kMaxFilterLength + 1> m{};
  for (std::uint32_t d = 1; d <= kMaxFilterLength; ++d) m[d] = Reciprocal63(d);
  return m;
}();

}  // namespace

void WrenchCore::SetCalibration(const FixedCalibration& cal) {
  cal_ = cal;
  BuildPlan();
  ClearTare();
  ResetFilter();
  last_valid_ = {};
}

bool WrenchCore::RequestTare(std::uint16_t samples) {
  if (samples < 1 || samples > kMaxTareSamples) return false;
  tare_sum_ = {};
  tare_temp_sum_ = 0;
  tare_total_ = samples;
  tare_remaining_ = samples;
  return true;
}

void WrenchCore::ClearTare() {
  tare_active_ = false;
  tare_remaining_ = 0;
  tare_counts_ = {};
  tare_offset_ = {};
  tare_acc_ = {};
  UpdateEffective(eff_dt_);
}

void WrenchCore::BuildPlan() {
  plan_ = Plan{};
  narrow_linear_ = nullptr;
  eff_dt_ = 0;
  const std::size_t n = cal_.channel_count;
  if (!cal_.valid || n > kMaxChannels || cal_.extra_count > kMaxFeatures - kMaxChannels) return;
  for (std::size_t c = 0; c < n; ++c) {
    plan_.zero[c] = cal_.zero[c];
    for (std::size_t r = 0; r < kAxes; ++r) plan_.coef[c][r] = cal_.coef[r][c];
  }
  std::size_t p = 0;
  for (std::size_t k = 0; k < cal_.extra_count; ++k) {
    const FixedFeature& e = cal_.extra[k];
    const std::int64_t half = e.shift > 0 ? std::int64_t{1} << (e.shift - 1) : 0;
    switch (e.kind) {
      case FeatureKind::kTemperature:
        for (std::size_t r = 0; r < kAxes; ++r) plan_.temp_coef[r] = cal_.coef[r][n + k];
        plan_.temperature = true;
        break;
      case FeatureKind::kProduct:
        plan_.a[p] = e.a;
        plan_.b[p] = e.b;
        plan_.shift[p] = e.shift;
        plan_.half[p] = half;
        for (std::size_t r = 0; r < kAxes; ++r) plan_.quad[p][r] = cal_.coef[r][n + k];
        ++p;
        break;
      case FeatureKind::kTempProduct:
        for (std::size_t r = 0; r < kAxes; ++r) plan_.drift[e.a][r] = cal_.coef[r][n + k];
        plan_.drift_shift[e.a] = e.shift;
        plan_.drift_half[e.a] = half;
        plan_.temperature = true;
        break;
    }
  }
  plan_.channels = static_cast<std::uint8_t>(n);
  plan_.products = static_cast<std::uint8_t>(p);
  for (std::size_t r = 0; r < kAxes; ++r) {
    if ((cal_.invalid_axes & (1u << r)) == 0) continue;
    // Not determined by the calibration: a zero row reads 0 (status bit 10), never a value.
    for (auto& col : plan_.coef) col[r] = 0;
    for (auto& col : plan_.drift) col[r] = 0;
    for (auto& col : plan_.quad) col[r] = 0;
    plan_.temp_coef[r] = 0;
  }
  plan_.narrow = cal_.narrow;
  for (std::size_t r = 0; r < kAxes; ++r) {
    // k ≤ s always holds where the loader chose the narrow form (its rounding ≤ 1/16 LSB needs
    // 2^k < 2^s); checked here because ApplyNarrow relies on it.
    if (cal_.narrow_shift[r] > cal_.shift[r]) plan_.narrow = false;
    plan_.final_shift[r] = static_cast<std::uint8_t>(cal_.shift[r] - cal_.narrow_shift[r]);
    plan_.final.shift[r] = plan_.final_shift[r];
    plan_.final.offset[r] =
        (std::uint64_t{1} << 31) - (std::uint64_t{1} << (63 - plan_.final_shift[r]));
  }
  plan_.narrow_shift = cal_.narrow_shift;
  plan_.narrow_product_shift = cal_.narrow_product_shift;
  for (std::size_t r = 0; r < kAxes; ++r) {
    const std::uint8_t k = plan_.narrow_shift[r];
    plan_.narrow_half[r] = k > 0 ? std::int64_t{1} << (k - 1) : 0;  // RoundShift's half
  }
  for (std::size_t c = 0; c < n; ++c) {
    plan_.lo_minus_zero[c] =
        static_cast<std::uint64_t>(std::int64_t{cal_.min_counts} - plan_.zero[c]);
  }
  if (plan_.narrow && p == 0 && n >= 1) {
    static constexpr std::array<LinearFn, kMaxChannels> kLinear = {
        &WrenchCore::ApplyNarrowLinear<1>, &WrenchCore::ApplyNarrowLinear<2>,
        &WrenchCore::ApplyNarrowLinear<3>, &WrenchCore::ApplyNarrowLinear<4>,
        &WrenchCore::ApplyNarrowLinear<5>, &WrenchCore::ApplyNarrowLinear<6>,
        &WrenchCore::ApplyNarrowLinear<7>, &WrenchCore::ApplyNarrowLinear<8>};
    narrow_linear_ = kLinear[n - 1];
  }
  for (std::size_t r = 0; r < kAxes && plan_.narrow; ++r) {
    std::uint64_t sum = 0;
    for (std::size_t j = 0; j < p; ++j) {
      // |q'| ≤ 2^31 − 1 (NarrowRow): q' + 2^31 fits 32 bits.
      plan_.quad_u[j][r] = static_cast<std::uint64_t>(
          RoundShift(plan_.quad[j][r], plan_.narrow_product_shift[r]) + kHalf32);
      sum += plan_.quad_u[j][r];
    }
    plan_.quad_k[r] = (sum << 31) - (std::uint64_t{p} << 62);  // modulo 2^64
  }
  for (std::size_t r = 0; r < kAxes; ++r) {
    if ((cal_.invalid_axes & (1u << r)) != 0) continue;  // a zero row
    // The bias with the counts' origin moved to zero (Σ coef_c·counts_c = Σ coef_c·x̃_c + this).
    plan_.bias[r] = cal_.bias[r];
    for (std::size_t c = 0; c < n; ++c) plan_.bias[r] += cal_.coef[r][c] * cal_.zero[c];
    plan_.round_half[r] = cal_.shift[r] > 0 ? std::int64_t{1} << (cal_.shift[r] - 1) : 0;
  }
}

void WrenchCore::Effective(std::int32_t dt_mdegc, Columns& eff,
                           std::array<std::int64_t, kAxes>& k) const {
  // K = bias + Σ_c coef_c·zero_c + coef_ΔT·ΔT and eff_c = coef_c + d_c with d_c =
  // round(C_c·ΔT / 2^h_c), multiplied by x̃_c = counts_c − zero_c: C_c·x̃_c·ΔT/2^h rounded once
  // per temperature. The loader proved |C_c·ΔT| + half < 2^63 and the sums' bound
  // (EvaluationFits).
  const std::int64_t dt = dt_mdegc;
  for (std::size_t r = 0; r < kAxes; ++r) k[r] = plan_.bias[r] + plan_.temp_coef[r] * dt;
  for (std::size_t c = 0; c < plan_.channels; ++c) {
    const std::uint8_t h = plan_.drift_shift[c];
    for (std::size_t r = 0; r < kAxes; ++r) {
      const std::int64_t d = (plan_.drift[c][r] * dt + plan_.drift_half[c]) >> h;
      eff[c][r] = plan_.coef[c][r] + d;
    }
  }
}

void WrenchCore::UpdateEffective(std::int32_t dt_mdegc) const {
  eff_dt_ = dt_mdegc;
  if (!plan_.narrow) {
    std::array<std::int64_t, kAxes> k{};
    Effective(dt_mdegc, eff_, k);
    // With the final rounding half: Apply shifts acc right without adding it (the loader's bound
    // covers every partial sum plus the half, in any order).
    for (std::size_t r = 0; r < kAxes; ++r) konst_[r] = k[r] - tare_acc_[r] + plan_.round_half[r];
    return;
  }
  // The narrow form reads only narrow_tab_ and narrow_low_: Effective's values, rounded to the
  // narrow coefficients as they are made (eff_ is not kept).
  const std::int64_t dt = dt_mdegc;
  std::array<std::uint64_t, kAxes> base{};  // Σ_c c'·(lo − zero_c), modulo 2^64
  for (std::size_t c = 0; c < plan_.channels; ++c) {
    const std::uint8_t h = plan_.drift_shift[c];
    const std::uint64_t lz = plan_.lo_minus_zero[c];
    for (std::size_t r = 0; r < kAxes; ++r) {
      const std::int64_t d = (plan_.drift[c][r] * dt + plan_.drift_half[c]) >> h;
      // |eff'| ≤ 2^31 − 1 at every ΔT in range (NarrowRow): eff' + 2^31 fits 32 bits.
      const std::int64_t e = (plan_.coef[c][r] + d + plan_.narrow_half[r]) >> plan_.narrow_shift[r];
      narrow_tab_.coef_u[c][r] = static_cast<std::uint64_t>(e + kHalf32);
      narrow_tab_.coef_u32[c][r] = static_cast<std::uint32_t>(e + kHalf32);
      base[r] += static_cast<std::uint64_t>(e) * lz;
    }
  }
  for (std::size_t r = 0; r < kAxes; ++r) {
    // K with the final rounding half (see above); floor(K/2^k) + base and K mod 2^k.
    konst_[r] = plan_.bias[r] + plan_.temp_coef[r] * dt - tare_acc_[r] + plan_.round_half[r];
    const std::uint8_t ks = plan_.narrow_shift[r];
    narrow_tab_.konst[r] = static_cast<std::uint64_t>(konst_[r] >> ks) + base[r];
    narrow_low_[r] = konst_[r] & ((std::int64_t{1} << ks) - 1);
  }
}

// Inlined into Apply: the per-sample sum over the counts and the second-order features.
[[gnu::always_inline]] inline void WrenchCore::Accumulate(
    const std::array<std::int32_t, kMaxChannels>& v, const Columns& eff,
    std::array<std::int64_t, kAxes>& acc) const {
  const std::size_t n = plan_.channels;
  std::array<std::int64_t, kMaxChannels> x{};  // x̃ = counts − zero
  for (std::size_t c = 0; c < n; ++c) {
    const std::int64_t xc = std::int64_t{v[c]} - plan_.zero[c];
    x[c] = xc;
    for (std::size_t r = 0; r < kAxes; ++r) acc[r] += eff[c][r] * xc;
  }
  // The loader checked |x̃_a·x̃_b| + half ≤ 2^63 − 1 (kFeatureOverflow) and sized the shifts.
  for (std::size_t j = 0; j < plan_.products; ++j) {
    const std::int64_t p = (x[plan_.a[j]] * x[plan_.b[j]] + plan_.half[j]) >> plan_.shift[j];
    const auto& q = plan_.quad[j];
    for (std::size_t r = 0; r < kAxes; ++r) acc[r] += q[r] * p;
  }
}

// Inlined into Apply: the narrow form (see Plan::narrow and narrow::Table). The counts sum runs
// in 32x32→64-bit lanes; the second-order features, when present, in a second group of lanes.
template <std::size_t N>
void WrenchCore::ApplyNarrowLinear(const std::array<std::int32_t, kMaxChannels>& counts,
                                   WrenchLsb& y, bool* saturated) const {
  // Clamped counts (unused here) and t = floor(acc/2^k) exactly (its true value is bounded by
  // the loader): one more shift.
  std::array<std::int32_t, kMaxChannels> v;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<std::uint64_t, kAxes> t;        // NOLINT(cppcoreguidelines-pro-type-member-init)
  bool sat = narrow::CountsSum<N>(counts, cal_.min_counts, cal_.max_counts, narrow_tab_, v, t);
  if (!narrow::ShiftToI32(t, plan_.final, y)) {  // some axis beyond int32: saturate
    for (std::size_t r = 0; r < kAxes; ++r) {
      y[r] = SatToI32(static_cast<std::int64_t>(t[r]) >> plan_.final_shift[r], &sat);
    }
  }
  if (sat) *saturated = true;
}

[[gnu::always_inline]] inline void WrenchCore::ApplyNarrow(
    const std::array<std::int32_t, kMaxChannels>& counts, std::array<std::int64_t, kAxes>& q,
    bool& clamped) const {
  // Clamped counts: only [0, n) is written and read.
  std::array<std::int32_t, kMaxChannels> v;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<std::uint64_t, kAxes> t;        // NOLINT(cppcoreguidelines-pro-type-member-init)
  clamped |= narrow::CountsSumN(plan_.channels, counts, cal_.min_counts, cal_.max_counts,
                                narrow_tab_, v, t);
  std::array<std::int64_t, kMaxChannels> x;  // NOLINT: x̃ = v − zero, [0, n) written and read
  for (std::size_t c = 0; c < plan_.channels; ++c) x[c] = std::int64_t{v[c]} - plan_.zero[c];
  std::uint64_t psum = 0;  // Σ p'_u
  narrow::Sums6 sums;
  for (std::size_t j = 0; j < plan_.products; ++j) {
    // The loader checked |x̃_a·x̃_b| + half ≤ 2^63 − 1 (kFeatureOverflow) and sized the shifts.
    const std::int64_t p = (x[plan_.a[j]] * x[plan_.b[j]] + plan_.half[j]) >> plan_.shift[j];
    const auto pu = static_cast<std::uint64_t>(p + kHalf32);  // |p| < 2^31 (NarrowRow)
    psum += pu;
    sums.Add(plan_.quad_u[j], pu);
  }
  std::array<std::uint64_t, kAxes> sum;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  sums.Store(sum);
  for (std::size_t r = 0; r < kAxes; ++r) {
    // acc = T·2^k + (K mod 2^k) + (Σ q'·p)·2^k2, modulo 2^64 (the true acc is bounded).
    const std::uint64_t quad = sum[r] - plan_.quad_k[r] - (psum << 31);
    const std::uint64_t acc = (t[r] << plan_.narrow_shift[r]) +
                              static_cast<std::uint64_t>(narrow_low_[r]) +
                              (quad << plan_.narrow_product_shift[r]);
    q[r] = static_cast<std::int64_t>(acc) >> cal_.shift[r];
  }
}

bool WrenchCore::SetFilterLength(std::uint16_t length) {
  if (length < 1 || length > kMaxFilterLength) return false;
  filter_length_ = length;
  ResetFilter();
  return true;
}

void WrenchCore::ResetFilter() {
  filter_fill_ = 0;
  filter_pos_ = 0;
  filter_sum_ = {};
}

void WrenchCore::Apply(const std::array<std::int32_t, kMaxChannels>& counts, WrenchLsb& y,
                       bool* saturated) const {
  bool temp_range = false;
  Apply(counts, cal_.temp_ref_mdegc, true, y, saturated, &temp_range);
}

std::int32_t WrenchCore::DeltaT(std::int32_t temperature_mdegc, bool has_temperature,
                                bool* out_of_range) const {
  if (!cal_.temperature) return 0;
  std::int32_t t = has_temperature ? temperature_mdegc : cal_.temp_ref_mdegc;
  if (!has_temperature) *out_of_range = true;
  if (t > cal_.temp_max_mdegc) {
    t = cal_.temp_max_mdegc;
    *out_of_range = true;
  } else if (t < cal_.temp_min_mdegc) {
    t = cal_.temp_min_mdegc;
    *out_of_range = true;
  }
  return t - cal_.temp_ref_mdegc;
}

void WrenchCore::Apply(const std::array<std::int32_t, kMaxChannels>& counts,
                       std::int32_t temperature_mdegc, bool has_temperature, WrenchLsb& y,
                       bool* saturated, bool* temp_range) const {
  // The hot path: y_r = round((K_r + Σ_c eff[c][r]·v_c + Σ_j quad[j][r]·p_j) / 2^shift_r) with
  // K and eff cached per ΔT (temperature changes slowly); with a tare K holds minus the tare's
  // sum, so the bias drops out (see FixedCalibration).
  const std::size_t n = plan_.channels;
  bool clamped = false;
  if (plan_.temperature) {
    const std::int32_t dt = DeltaT(temperature_mdegc, has_temperature, temp_range);
    if (dt != eff_dt_) UpdateEffective(dt);
  }
  if (narrow_linear_ != nullptr) {  // narrow, no second-order features: one instance per N
    (this->*narrow_linear_)(counts, y, saturated);
    return;
  }
  // The loader guarantees every partial sum stays within ±2^62 (EvaluationFits). konst_ holds
  // the rounding half. An axis the calibration does not determine has all-zero rows in the plan:
  // it reads 0.
  std::array<std::int64_t, kAxes> q;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  if (plan_.narrow) {
    ApplyNarrow(counts, q, clamped);  // clamps the counts itself
  } else {
    std::array<std::int32_t, kMaxChannels> v{};
    for (std::size_t c = 0; c < n; ++c) {
      v[c] = std::min(std::max(counts[c], cal_.min_counts), cal_.max_counts);  // branch-free
      clamped |= v[c] != counts[c];
    }
    std::array<std::int64_t, kAxes> acc = konst_;
    Accumulate(v, eff_, acc);
    for (std::size_t r = 0; r < kAxes; ++r) q[r] = acc[r] >> cal_.shift[r];
  }
  std::uint64_t outside = 0;  // bits ≥ 32 set when some q is outside int32
  for (std::size_t r = 0; r < kAxes; ++r) {
    outside |= static_cast<std::uint64_t>(q[r]) + (std::uint64_t{1} << 31);
    y[r] = static_cast<std::int32_t>(q[r]);
  }
  if ((outside >> 32) != 0) {
    for (std::size_t r = 0; r < kAxes; ++r) y[r] = SatToI32(q[r], &clamped);
  }
  if (clamped) *saturated = true;
}

bool WrenchCore::FirstSampleRailsAreLoad(const hal::AdcSample& in) const {
  // Powered up under load, bridges are already at their rails: no previous sample tells a ramp
  // from a jump. A load drives several bridges together; an open or shorted gauge pins one. So
  // two or more channels at the same rail read as a load (overload evidence); a single channel
  // at a rail reads as a bridge fault until it leaves the rail.
  int at_max = 0;
  int at_min = 0;
  for (std::size_t c = 0; c < in.channel_count && c < kMaxChannels; ++c) {
    const bool flagged = (in.flags[c] & hal::kChannelSaturated) != 0;
    const std::int64_t mid = (std::int64_t{cal_.max_counts} + cal_.min_counts) / 2;
    if (in.counts[c] >= cal_.max_counts || (flagged && in.counts[c] > mid)) ++at_max;
    if (in.counts[c] <= cal_.min_counts || (flagged && in.counts[c] <= mid)) ++at_min;
  }
  return at_max >= 2 || at_min >= 2;
}

// The per-sample stages are inlined into Process: the split is for reading, not a call each.
[[gnu::always_inline]] inline WrenchCore::Faults WrenchCore::DetectFaults(const hal::AdcSample& in,
                                                                          CoreOutput& out) {
  const std::size_t n = in.channel_count;
  Faults f;
  bool all_same = n > 0;
  // The first sample has no path to judge: see FirstSampleRailsAreLoad.
  const bool first_is_load = !seen_sample_ && FirstSampleRailsAreLoad(in);
  for (std::size_t c = 0; c < n && c < kMaxChannels; ++c) {
    const std::int32_t v = in.counts[c];
    const bool at_rail = cal_.valid && (v >= cal_.max_counts || v <= cal_.min_counts);
    const bool flagged = (in.flags[c] & hal::kChannelSaturated) != 0;
    const bool sat = at_rail || flagged;
    if (sat && !seen_sample_) {
      rail_jump_[c] = !first_is_load;
    } else if (sat && !was_saturated_[c]) {
      // Entering saturation from inside the middle half of the range in one sample: a jump.
      const std::int64_t mid = (std::int64_t{cal_.max_counts} + cal_.min_counts) / 2;
      const std::int64_t quarter = (std::int64_t{cal_.max_counts} - cal_.min_counts) / 4;
      const std::int64_t prev = last_counts_[c];
      rail_jump_[c] = prev - mid < quarter && mid - prev < quarter;
    }
    was_saturated_[c] = sat;
    if (flagged) f.any_saturated = true;  // the backend's saturation flag (within 1 % of a rail)
    if (sat && rail_jump_[c]) f.jumped = true;
    if ((in.flags[c] & (hal::kChannelReadError | hal::kChannelTimeout)) != 0) f.any_error = true;
    if (v != last_counts_[c]) all_same = false;
    rail_run_[c] = at_rail ? static_cast<std::uint16_t>(rail_run_[c] < 0xFFFF ? rail_run_[c] + 1
                                                                              : rail_run_[c])
                           : 0;
    if (limits_.rail_samples > 0 && rail_run_[c] >= limits_.rail_samples && rail_jump_[c]) {
      f.bridge_fault = true;
    }
    last_counts_[c] = v;
  }
  seen_sample_ = true;
  same_count_run_ = all_same ? static_cast<std::uint16_t>(
                                   same_count_run_ < 0xFFFF ? same_count_run_ + 1 : same_count_run_)
                             : 0;
  if (f.any_saturated) out.status |= kStatusSaturated;
  if (f.bridge_fault) out.status |= kStatusBridgeFault;
  if (f.any_error || (limits_.stuck_samples > 0 && same_count_run_ >= limits_.stuck_samples)) {
    out.status |= kStatusAdcFault;
  }
  return f;
}

[[gnu::always_inline]] inline void WrenchCore::AccumulateTare(const hal::AdcSample& in,
                                                              std::int32_t dt_mdegc) {
  const std::size_t n = in.channel_count;
  for (std::size_t c = 0; c < n; ++c) tare_sum_[c] += in.counts[c];
  tare_temp_sum_ += dt_mdegc;
  if (--tare_remaining_ == 0) {
    for (std::size_t c = 0; c < n; ++c) {
      const std::int64_t avg = RoundDiv(tare_sum_[c], tare_total_);  // between the rails
      tare_counts_[c] = static_cast<std::int32_t>(
          avg > cal_.max_counts ? cal_.max_counts
                                : (avg < cal_.min_counts ? cal_.min_counts : avg));
    }
    // The untared sum at the tare, as Apply computes it (bounded by the loader like any sample):
    // tared sums subtract it, so every feature is taken relative to its value at the tare.
    const auto dt_tare = static_cast<std::int32_t>(RoundDiv(tare_temp_sum_, tare_total_));
    Columns eff{};
    std::array<std::int64_t, kAxes> acc{};
    Effective(dt_tare, eff, acc);
    Accumulate(tare_counts_, eff, acc);
    bool clipped = false;
    for (std::size_t r = 0; r < kAxes; ++r) {
      tare_acc_[r] = acc[r];
      // The wrench of the tare itself (untared − tared): an undetermined axis stays 0.
      tare_offset_[r] = (cal_.invalid_axes & (1u << r)) != 0
                            ? 0
                            : SatToI32(RoundShift(acc[r], cal_.shift[r]), &clipped);
    }
    tare_active_ = true;
    UpdateEffective(eff_dt_);
    ResetFilter();
  }
}

[[gnu::always_inline]] inline void WrenchCore::Filter(const WrenchLsb& y, CoreOutput& out) {
  auto& slot = filter_ring_[filter_pos_];
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (filter_fill_ == filter_length_) filter_sum_[r] -= slot[r];
    filter_sum_[r] += y[r];
    slot[r] = y[r];
  }
  if (filter_fill_ < filter_length_) ++filter_fill_;
  if (++filter_pos_ == filter_length_) filter_pos_ = 0;
  if (filter_fill_ == 1) {
    out.wrench = y;  // no averaging: skip the divisions
  } else {
    // |sum| ≤ 256·2^31 = 2^39: within RoundDivByReciprocal's exact range (no division per axis).
    const std::uint64_t m = kFillReciprocal[filter_fill_];
    for (std::size_t r = 0; r < kAxes; ++r) {
      out.wrench[r] = SatToI32(RoundDivByReciprocal(filter_sum_[r], filter_fill_, m),
                               &out.arithmetic_saturated);
    }
  }
}

void WrenchCore::Process(const hal::AdcSample& in, bool simulated, CoreOutput& out) {
  out.status = simulated ? kStatusSimulated : 0;
  out.arithmetic_saturated = false;
  out.updated = false;
  const std::size_t n = in.channel_count;
  const Faults faults = DetectFaults(in, out);

  if (!cal_.valid || n != cal_.channel_count) {
    out.status |= kStatusCalInvalid;
    out.wrench = {};
    out.unfiltered = {};
    out.structural = {};
    out.structural_valid = false;
    out.saturated_by_load = false;
    return;
  }

  if (cal_.invalid_axes != 0) out.status |= kStatusAxisInvalid;
  const bool usable = !faults.any_saturated && !faults.any_error && !faults.bridge_fault;
  bool temp_range = false;
  const std::int32_t dt_mdegc = DeltaT(in.temperature_mdegc, in.has_temperature, &temp_range);
  if (temp_range) out.status |= kStatusTempRange;
  // Tare accumulates only on usable samples.
  if (usable && tare_remaining_ > 0) AccumulateTare(in, dt_mdegc);
  if (tare_active_) out.status |= kStatusTareActive;

  // The load on the body (untared, unfiltered). While a bridge is saturated its counts are
  // clamped at the rails by Apply, so this is a lower bound of the load — still the evidence the
  // overload rule needs. Not on read errors or a broken bridge: those counts mean nothing.
  WrenchLsb y{};
  out.structural_valid = !faults.any_error && !faults.bridge_fault && !faults.jumped;
  out.saturated_by_load = faults.any_saturated && !faults.jumped;
  if (out.structural_valid) {
    bool clipped = false;
    Apply(in.counts, in.temperature_mdegc, in.has_temperature, y, &clipped, &temp_range);
    for (std::size_t r = 0; r < kAxes; ++r) {
      out.structural[r] = SatToI32(std::int64_t{y[r]} + tare_offset_[r], &clipped);
    }
    if (usable) out.arithmetic_saturated = out.arithmetic_saturated || clipped;
  } else {
    out.structural = {};
  }

  if (!usable) {  // hold the last valid wrench (the publication marks it invalid)
    out.wrench = last_valid_;
    return;
  }
  out.unfiltered = y;
  Filter(y, out);
  last_valid_ = out.wrench;
  out.updated = true;
}

}  // namespace ftstack::fw
