#include "firmware/core.hpp"

#include "firmware/fixed_point.hpp"

namespace ftstack::fw {

namespace {

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
  tare_extra_ = {};
  tare_offset_ = {};
  tare_f_ = {};
}

void WrenchCore::BuildPlan() {
  plan_ = Plan{};
  const std::size_t n = cal_.channel_count;
  if (!cal_.valid || n > kMaxChannels || cal_.extra_count > kMaxFeatures - kMaxChannels) return;
  std::size_t j = 0;
  auto add = [&](std::size_t cal_index) {  // cal_index: the feature's column in cal_.coef
    for (std::size_t r = 0; r < kAxes; ++r) plan_.coef[j][r] = cal_.coef[r][cal_index];
    if (cal_index >= n) {
      const FixedFeature& e = cal_.extra[cal_index - n];
      plan_.source[j] = static_cast<std::uint8_t>(cal_index - n);
      plan_.a[j] = e.a;
      plan_.b[j] = e.b;
      plan_.shift[j] = e.shift;
      plan_.half[j] = e.shift > 0 ? std::int64_t{1} << (e.shift - 1) : 0;
    }
    ++j;
  };
  for (std::size_t c = 0; c < n; ++c) add(c);
  for (FeatureKind kind :
       {FeatureKind::kTemperature, FeatureKind::kProduct, FeatureKind::kTempProduct}) {
    for (std::size_t k = 0; k < cal_.extra_count; ++k) {
      if (cal_.extra[k].kind == kind) add(n + k);
    }
    if (kind == FeatureKind::kTemperature) plan_.temp_end = static_cast<std::uint8_t>(j);
    if (kind == FeatureKind::kProduct) plan_.product_end = static_cast<std::uint8_t>(j);
  }
  plan_.channels = static_cast<std::uint8_t>(n);
  plan_.features = static_cast<std::uint8_t>(j);
  for (std::size_t r = 0; r < kAxes; ++r) {
    plan_.round_half[r] = cal_.shift[r] > 0 ? std::int64_t{1} << (cal_.shift[r] - 1) : 0;
  }
}

void WrenchCore::BuildTareFeatures() {
  const std::size_t n = cal_.channel_count;
  tare_f_ = {};
  if (!tare_active_) return;
  for (std::size_t c = 0; c < n; ++c) tare_f_[c] = tare_counts_[c];
  for (std::size_t j = n; j < plan_.features; ++j) tare_f_[j] = tare_extra_[plan_.source[j]];
}

void WrenchCore::ComputeTareOffset() {
  // Untared y = Σ coef·x + Σ coef·f + bias; tared y = Σ coef·(x − tare) + Σ coef·(f − f_tare).
  // Their difference is Σ coef·tare + Σ coef·f_tare + bias, a constant of the tare. The loader
  // bounds every such sum below 2^62 for counts between the rails (tare counts are averages of
  // such counts), so the accumulation cannot overflow. Rounding each separately: ≤ 1 LSB apart.
  const std::size_t n = cal_.channel_count;
  bool clipped = false;
  for (std::size_t r = 0; r < kAxes; ++r) {
    if ((cal_.invalid_axes & (1u << r)) != 0) {
      tare_offset_[r] = 0;  // an axis the calibration does not determine stays 0
      continue;
    }
    std::int64_t acc = cal_.bias[r];
    for (std::size_t c = 0; c < n; ++c) acc += cal_.coef[r][c] * tare_counts_[c];
    for (std::size_t k = 0; k < cal_.extra_count; ++k) acc += cal_.coef[r][n + k] * tare_extra_[k];
    tare_offset_[r] = SatToI32(RoundShift(acc, cal_.shift[r]), &clipped);
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

void WrenchCore::ExtraFeatures(const std::array<std::int32_t, kMaxChannels>& counts,
                               std::int32_t dt_mdegc,
                               std::array<std::int64_t, kMaxFeatures - kMaxChannels>& f) const {
  for (std::size_t k = 0; k < cal_.extra_count; ++k) {
    const FixedFeature& e = cal_.extra[k];
    switch (e.kind) {
      case FeatureKind::kTemperature:
        f[k] = dt_mdegc;
        break;
      case FeatureKind::kProduct: {
        // The loader proved |x̃_a·x̃_b| + 2^(shift−1) ≤ 2^63 − 1 (RawProductFits): no overflow.
        const std::int64_t xa = static_cast<std::int64_t>(counts[e.a]) - cal_.zero[e.a];
        const std::int64_t xb = static_cast<std::int64_t>(counts[e.b]) - cal_.zero[e.b];
        f[k] = RoundShift(xa * xb, e.shift);
        break;
      }
      case FeatureKind::kTempProduct: {
        const std::int64_t xa = static_cast<std::int64_t>(counts[e.a]) - cal_.zero[e.a];
        f[k] = RoundShift(xa * dt_mdegc, e.shift);
        break;
      }
    }
  }
}

void WrenchCore::Apply(const std::array<std::int32_t, kMaxChannels>& counts,
                       std::int32_t temperature_mdegc, bool has_temperature, WrenchLsb& y,
                       bool* saturated, bool* temp_range) const {
  // The hot path: y_r = round((Σ_j coef[r][j]·f_j + bias_r) / 2^shift_r), features in plan order.
  // Without a tare tare_f_ is zero; with one the bias drops out (see FixedCalibration).
  const std::size_t n = plan_.channels;
  const std::size_t nf = plan_.features;
  // Features; only [0, nf) are written and read (zeroing all 53 each sample would cost time).
  std::array<std::int64_t, kMaxFeatures> f;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<std::int64_t, kMaxChannels> x_zero{};  // clamped counts − zero (products' origin)
  bool clamped = false;
  for (std::size_t c = 0; c < n; ++c) {
    const std::int32_t raw = counts[c];
    const std::int32_t v =
        raw > cal_.max_counts ? cal_.max_counts : (raw < cal_.min_counts ? cal_.min_counts : raw);
    clamped |= v != raw;
    f[c] = v - tare_f_[c];
    x_zero[c] = static_cast<std::int64_t>(v) - cal_.zero[c];
  }
  if (nf > n) {
    const std::int64_t dt = DeltaT(temperature_mdegc, has_temperature, temp_range);
    std::size_t j = n;
    for (; j < plan_.temp_end; ++j) f[j] = dt;
    // The loader checked |x̃_a·x̃_b| + half ≤ 2^63 − 1 (kFeatureOverflow) and sized the shifts.
    for (; j < plan_.product_end; ++j) {
      f[j] = (x_zero[plan_.a[j]] * x_zero[plan_.b[j]] + plan_.half[j]) >> plan_.shift[j];
    }
    for (; j < nf; ++j) f[j] = (x_zero[plan_.a[j]] * dt + plan_.half[j]) >> plan_.shift[j];
    for (j = n; j < nf; ++j) f[j] -= tare_f_[j];
  }
  // The loader guarantees Σ|coef|·|f| + |bias| ≤ 2^61 for every input between the rails, so no
  // partial sum in any order can overflow.
  std::array<std::int64_t, kAxes> acc{};
  for (std::size_t r = 0; r < kAxes; ++r) acc[r] = tare_active_ ? 0 : cal_.bias[r];
  for (std::size_t j = 0; j < nf; ++j) {
    const std::int64_t fj = f[j];
    const auto& col = plan_.coef[j];
    for (std::size_t r = 0; r < kAxes; ++r) acc[r] += col[r] * fj;
  }
  for (std::size_t r = 0; r < kAxes; ++r) {
    if ((cal_.invalid_axes & (1u << r)) != 0) {
      y[r] = 0;  // not determined by the calibration: never a value (status bit 10)
      continue;
    }
    y[r] = SatToI32((acc[r] + plan_.round_half[r]) >> cal_.shift[r], &clamped);
  }
  if (clamped) *saturated = true;
}

// The per-sample stages are inlined into Process: the split is for reading, not a call each.
[[gnu::always_inline]] inline WrenchCore::Faults WrenchCore::DetectFaults(const hal::AdcSample& in,
                                                                          CoreOutput& out) {
  const std::size_t n = in.channel_count;
  Faults f;
  bool all_same = n > 0;
  for (std::size_t c = 0; c < n && c < kMaxChannels; ++c) {
    const std::int32_t v = in.counts[c];
    const bool at_rail = cal_.valid && (v >= cal_.max_counts || v <= cal_.min_counts);
    const bool flagged = (in.flags[c] & hal::kChannelSaturated) != 0;
    const bool sat = at_rail || flagged;
    if (sat && !was_saturated_[c]) {
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
      tare_counts_[c] = static_cast<std::int32_t>(RoundDiv(tare_sum_[c], tare_total_));
    }
    if (cal_.extra_count > 0) {
      ExtraFeatures(tare_counts_, static_cast<std::int32_t>(RoundDiv(tare_temp_sum_, tare_total_)),
                    tare_extra_);
    }
    tare_active_ = true;
    BuildTareFeatures();
    ComputeTareOffset();
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
