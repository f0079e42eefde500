#include "firmware/health_watch.hpp"

#include <algorithm>

#include "firmware/health_int.hpp"
#include "firmware/overload.hpp"
#include "firmware/status_bits.hpp"

namespace ftstack::fw {

static_assert(RainflowCounter::kBins == kRainflowBins);
namespace {

constexpr std::int64_t kZeroClamp = std::int64_t{1} << 20;  ///< |zero point| used, LSB
constexpr std::uint32_t kPointsHalve = 1u << 20;  ///< regression sums halve beyond this many points
constexpr std::uint32_t kCommissionBlocks = 50;   ///< 5 s of blocks

using health_int::Abs;
using health_int::Log2Floor;
using health_int::Sat32;

}  // namespace

bool HealthWatch::Configure(std::uint32_t rate_hz, const WrenchLsb& rated_lsb) {
  configured_ = false;
  if (rate_hz < 100) return false;
  for (const std::int32_t r : rated_lsb) {
    if (r <= 0) return false;
  }
  rate_ = rate_hz;
  rated_ = rated_lsb;
  fast_shift_ = Log2Floor(rate_hz / 10);
  slow_shift_ = Log2Floor(rate_hz);
  block_ = rate_hz / 10;
  inv_sqrt_block_q16_ = (std::int64_t{1} << 16) / ISqrt64(block_);
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (!tone50_[r].Configure(50, rate_hz, block_) || !tone60_[r].Configure(60, rate_hz, block_)) {
      return false;
    }
  }
  max_diff_ = std::min(tone50_[0].max_diff(), tone60_[0].max_diff());
  // The level's sub-blocks: the fewest samples each that keep the ring within kLevelRing and
  // divide the block exactly (the ring then spans whole periods of 50 and 60 Hz).
  level_sub_ = 1;
  while (block_ / level_sub_ > kLevelRing || block_ % level_sub_ != 0) ++level_sub_;
  level_len_ = block_ / level_sub_;
  ResetLevel();
  capture_stride_ = rate_hz <= 2000 ? 1 : rate_hz / 1000;
  for (std::size_t r = 0; r < kAxes; ++r) {
    // Turning points beyond 2 % of rated (noise makes none); cycles of 10 % of rated and more.
    RainflowCounter::BinEdges edges{};
    for (std::size_t k = 0; k < edges.size(); ++k) {
      edges[k] =
          static_cast<std::int32_t>(std::int64_t{rated_lsb[r]} * kRainflowBinEdgesPct[k] / 100);
    }
    rainflow_[r].Configure(rated_lsb[r] / 50, rated_lsb[r] / 10, edges);
  }
  seg_len_ = 2 * rate_hz;
  configured_ = true;
  SetThresholds(th_);
  Clear();
  Commission();
  return true;
}

void HealthWatch::SetThresholds(const HealthThresholds& t) {
  th_ = t;
  for (std::size_t r = 0; r < kAxes; ++r) {
    const std::int64_t rated = rated_[r];
    window_[r] = rated * t.zero_window_bp / 10000;
    limit_[r] = rated * t.zero_limit_bp / 10000;
    band_[r] = rated * t.stability_bp / 10000;
    move_[r] = rated / 100;  // a load change: the raw sample 1 % of rated off the fast filter
    step_[r] = rated / 20;   // a transient worth capturing: 5 % of rated in one step
  }
  stable_samples_ = static_cast<std::uint32_t>(std::uint64_t{rate_} * t.stable_time_ds / 10);
  ring_ref_mhz_ = t.ring_ref_dhz != 0 ? std::int32_t{t.ring_ref_dhz} * 100 : ring_ref_mhz_;
}

void HealthWatch::Commission() {
  commission_blocks_ = kCommissionBlocks;
  sigma_ref_sum_q8_ = {};
  sigma_ref_q8_ = {};
  ring_learned_ = 0;
  if (th_.ring_ref_dhz == 0) ring_ref_mhz_ = 0;
}

void HealthWatch::Clear() {
  active_ = 0;
  error_ = {};
  ResetReference(0, false);  // the next sample's temperature becomes the reference
  ring_measured_ = 0;
  creep_streak_ = 0;
  for (RainflowCounter& c : rainflow_) c.Clear();
  cycles_changed_ = true;
}

void HealthWatch::OnTare(std::int32_t temperature_mdegc, bool has_temperature, bool cleared,
                         const WrenchLsb& load_lsb, TareSource source) {
  ResetReference(temperature_mdegc, has_temperature);
  if (cleared) return;
  tare_sample_ = static_cast<std::uint32_t>(samples_ / rate_);
  report_.tare_temp_mdegc = has_temperature ? temperature_mdegc : 0;
  ++report_.tare_count;
  if (tares_completed_ < UINT32_MAX) ++tares_completed_;
  // Newest first: the oldest record falls off the end (only at a tare, never per sample).
  auto& h = report_.tares;
  for (std::size_t k = kTareHistory - 1; k > 0; --k) h[k] = h[k - 1];
  h[0].number = tares_completed_;
  h[0].source = source;
  h[0].has_temperature = has_temperature;
  h[0].time_s = tare_sample_;
  h[0].temperature_mdegc = has_temperature ? temperature_mdegc : 0;
  h[0].load_lsb = load_lsb;
}

void HealthWatch::ResetReference(std::int32_t temperature_mdegc, bool has_temperature) {
  ref_sample_ = samples_;
  ref_temp_mdegc_ = temperature_mdegc;
  ref_has_temp_ = has_temperature;
  points_ = 0;
  stt_ = sdd_ = 0;
  szt_ = {};
  szd_ = {};
  szz_ = {};
  dtemp_min_ = dtemp_max_ = 0;
  stable_run_ = 0;
  zero_count_ = 0;
  zero_sum_ = {};
  report_.zero_drift_lsb = {};
  zero_last_ = {};
  spell_checked_ = false;
  SetFinding(HealthCause::kZeroDrift, false, {});
  SetFinding(HealthCause::kThermalZeroDrift, false, {});
  SetFinding(HealthCause::kOverloadShift, false, {});
  overload_seen_ = false;
  // The output jumps at a tare: no load change, transient or hold is judged across it.
  ResetFilters();
  capturing_ = false;
  analysing_ = kAxes;
  creep_phase_ = CreepPhase::kIdle;
  block_moved_ = true;
}

void HealthWatch::SetFinding(HealthCause cause, bool on, const WrenchLsb& error) {
  const std::size_t i = static_cast<std::size_t>(cause) - 1;
  const std::uint16_t bit = static_cast<std::uint16_t>(1u << i);
  if (on) {
    active_ = static_cast<std::uint16_t>(active_ | bit);
    error_[i] = error;
  } else {
    active_ = static_cast<std::uint16_t>(active_ & ~bit);
    error_[i] = {};
  }
}

void HealthWatch::Step(const HealthInput& in) {
  if (!configured_) return;
  ++samples_;
  // Also while the wrench is not valid (a bridge at a rail): an overload is what matters here.
  if ((in.status & kStatusOverload) != 0) overload_seen_ = true;
  if (in.untared_valid) {
    for (std::size_t r = 0; r < kAxes; ++r) {
      if (rainflow_[r].Add(in.untared[r])) cycles_changed_ = true;
    }
  }
  if (!in.valid) {
    ResetFilters();
    stable_run_ = 0;
    block_moved_ = true;
    capturing_ = false;
    creep_phase_ = CreepPhase::kIdle;
  } else {
    if (!ref_has_temp_ && in.has_temperature) {
      ref_temp_mdegc_ = in.temperature_mdegc;
      ref_has_temp_ = true;
    }
    if (!filters_ready_) {
      for (std::size_t r = 0; r < kAxes; ++r) {
        fast_q8_[r] = slow_q8_[r] = std::int64_t{in.tared[r]} * 256;
      }
      prev_ = in.tared;
      filters_ready_ = true;
    }
    // Moving and stable are judged on the 0.1 s level, in which a steady 50 or 60 Hz tone (and
    // its harmonics) cancels: a tone of any size is then not a load change.
    const bool moving = UpdateLevel(in);
    bool stable = level_filled_ >= level_len_;
    WrenchLsb d{};
    for (std::size_t r = 0; r < kAxes; ++r) {
      const std::int64_t y_q8 = std::int64_t{in.tared[r]} * 256;
      fast_q8_[r] += (y_q8 - fast_q8_[r]) >> fast_shift_;
      slow_q8_[r] += (y_q8 - slow_q8_[r]) >> slow_shift_;
      // |level − slow| within the band, compared in the ring's sum (no division per sample).
      const std::int64_t len = level_len_;
      stable = stable && Abs(level_sum_[r] * 256 - slow_q8_[r] * len) <= band_[r] * 256 * len;
      const std::int64_t diff = std::int64_t{in.tared[r]} - prev_[r];
      d[r] = static_cast<std::int32_t>(diff > max_diff_ ? max_diff_
                                                        : (diff < -max_diff_ ? -max_diff_ : diff));
    }
    prev_ = in.tared;
    if (moving) block_moved_ = true;
    UpdateZero(in, stable && !moving);
    UpdateBlock(in, d);
    UpdateRinging(in);
    UpdateCreep(in, moving);
  }
  Publish(in);
}

void HealthWatch::ResetLevel() {
  level_pos_ = 0;
  level_at_ = 0;
  level_filled_ = 0;
  level_acc_ = {};
  level_sum_ = {};
  level_moving_ = true;
}

bool HealthWatch::UpdateLevel(const HealthInput& in) {
  for (std::size_t r = 0; r < kAxes; ++r) level_acc_[r] += in.tared[r];
  if (++level_pos_ < level_sub_) return level_moving_;
  level_pos_ = 0;
  // The ring's old slots are not cleared at a reset (that would cost the whole ring in one
  // sample): while it fills, nothing leaves the sum.
  const bool full = level_filled_ >= level_len_;
  bool moving = false;
  for (std::size_t r = 0; r < kAxes; ++r) {
    const std::int32_t m = Sat32(
        level_sub_ == 1 ? level_acc_[r] : level_acc_[r] / static_cast<std::int64_t>(level_sub_));
    level_acc_[r] = 0;
    level_sum_[r] += m - (full ? level_ring_[r][level_at_] : 0);
    level_ring_[r][level_at_] = m;
    // The mean of the last 0.1 s against that of the previous whole window (0.1–0.2 s earlier):
    // a step shows at once, a ramp as its rise over 0.1–0.2 s.
    moving = moving ||
             Abs(level_sum_[r] - level_prev_[r]) > move_[r] * static_cast<std::int64_t>(level_len_);
  }
  if (level_filled_ <= level_len_) ++level_filled_;
  if (++level_at_ == level_len_) {
    level_at_ = 0;
    level_prev_ = level_sum_;
  }
  // Until a whole previous window exists, nothing is known: taken as moving.
  level_moving_ = moving || level_filled_ <= level_len_;
  return level_moving_;
}

void HealthWatch::UpdateZero(const HealthInput& in, bool stable) {
  bool unloaded = stable;
  for (std::size_t r = 0; r < kAxes && unloaded; ++r) {
    unloaded = Abs(level_sum_[r]) <= window_[r] * static_cast<std::int64_t>(level_len_);
  }
  if (!unloaded) {
    stable_run_ = 0;
    zero_count_ = 0;
    zero_sum_ = {};
    spell_checked_ = false;
    return;
  }
  if (stable_run_ < stable_samples_) {
    ++stable_run_;
    return;
  }
  for (std::size_t r = 0; r < kAxes; ++r) zero_sum_[r] += in.tared[r];
  if (++zero_count_ < rate_) return;
  AddZeroPoint(in);
  zero_count_ = 0;
  zero_sum_ = {};
}

void HealthWatch::AddZeroPoint(const HealthInput& in) {
  std::array<std::int64_t, kAxes> z{};
  bool jumped = false;
  for (std::size_t r = 0; r < kAxes; ++r) {
    z[r] = zero_sum_[r] / static_cast<std::int64_t>(zero_count_);
    z[r] = z[r] > kZeroClamp ? kZeroClamp : (z[r] < -kZeroClamp ? -kZeroClamp : z[r]);
    jumped = jumped || Abs(z[r] - zero_last_[r]) * 2 > limit_[r];
  }
  // A zero drifts slowly; a spell that starts more than half the limit away from the last zero
  // is a small load held still (a part in the gripper), not the zero: the whole spell is left out.
  if (!spell_checked_) {
    spell_checked_ = true;
    spell_rejected_ = jumped;
    // Unless an overload came between: a zero that jumps across one has shifted (the gauges or
    // the body yielded); the jump is the error. A part held still right after an overload reads
    // the same way and is flagged too: after an overload a check is due anyway.
    if (jumped && overload_seen_) {
      WrenchLsb shift{};
      for (std::size_t r = 0; r < kAxes; ++r) shift[r] = Sat32(z[r] - zero_last_[r]);
      SetFinding(HealthCause::kOverloadShift, true, shift);
    }
    overload_seen_ = false;
    Judged(HealthCause::kOverloadShift);
  }
  if (spell_rejected_) return;
  const std::int64_t dt_s = static_cast<std::int64_t>((samples_ - ref_sample_) / rate_);
  const bool temp = in.has_temperature && ref_has_temp_;
  const std::int64_t dtemp = temp ? (std::int64_t{in.temperature_mdegc} - ref_temp_mdegc_) / 10 : 0;
  if (points_ >= kPointsHalve) {  // forget the older half
    points_ /= 2;
    stt_ /= 2;
    sdd_ /= 2;
    for (std::size_t r = 0; r < kAxes; ++r) {
      szt_[r] /= 2;
      szd_[r] /= 2;
      szz_[r] /= 2;
    }
  }
  ++points_;
  stt_ += static_cast<Int128>(dt_s) * dt_s;
  sdd_ += static_cast<Int128>(dtemp) * dtemp;
  for (std::size_t r = 0; r < kAxes; ++r) {
    zero_last_[r] = z[r];
    report_.zero_drift_lsb[r] = static_cast<std::int32_t>(z[r]);
    szt_[r] += static_cast<Int128>(z[r]) * dt_s;
    szd_[r] += static_cast<Int128>(z[r]) * dtemp;
    szz_[r] += static_cast<Int128>(z[r]) * z[r];
  }
  if (dtemp < dtemp_min_) dtemp_min_ = static_cast<std::int32_t>(dtemp);
  if (dtemp > dtemp_max_) dtemp_max_ = static_cast<std::int32_t>(dtemp);
  JudgeZero(in);
}

void HealthWatch::JudgeZero(const HealthInput& in) {
  (void)in;
  bool drift = false;
  std::int64_t worst_ppm = 0;
  Int128 explained_temp = 0, explained_time = 0, total = 0;
  for (std::size_t r = 0; r < kAxes; ++r) {
    drift = drift || Abs(report_.zero_drift_lsb[r]) > limit_[r];
    total += szz_[r];
    // Regressions through the reference (the zero is 0 there): z = b·ΔT and z = a·Δt; the sum of
    // squares each explains is (Σ z·x)² / Σ x².
    if (sdd_ > 0) {
      explained_temp += szd_[r] * szd_[r] / sdd_;
      // b in LSB per 0.01 K → ppm of rated per K.
      const Int128 ppm = szd_[r] * 100 * 1000000 / (sdd_ * rated_[r]);
      const std::int64_t p = static_cast<std::int64_t>(ppm);
      if (Abs(p) > Abs(worst_ppm)) worst_ppm = p;
    }
    if (stt_ > 0) explained_time += szt_[r] * szt_[r] / stt_;
  }
  report_.thermal_ppm_per_k = Sat32(worst_ppm);
  Judged(HealthCause::kZeroDrift);
  if (dtemp_max_ - dtemp_min_ >= 100) Judged(HealthCause::kThermalZeroDrift);
  report_.zero_points = points_;
  // Thermal when the temperature moved ≥ 1 K and explains ≥ 3/4 of the zero's variation, and
  // at least as much as time does.
  const bool thermal = dtemp_max_ - dtemp_min_ >= 100 && explained_temp * 4 >= total * 3 &&
                       explained_temp >= explained_time;
  SetFinding(HealthCause::kThermalZeroDrift, drift && thermal, report_.zero_drift_lsb);
  SetFinding(HealthCause::kZeroDrift, drift && !thermal, report_.zero_drift_lsb);
}

void HealthWatch::UpdateBlock(const HealthInput& in, const WrenchLsb& d) {
  (void)in;
  for (std::size_t r = 0; r < kAxes; ++r) {
    tone50_[r].Add(d[r]);
    tone60_[r].Add(d[r]);
    sum_d_[r] += d[r];
    sum_d2_[r] += std::int64_t{d[r]} * d[r];
  }
  if (++block_pos_ < block_) return;
  FinishBlock();
}

void HealthWatch::FinishBlock() {
  const std::int64_t n = block_;
  BlockResult b;
  for (std::size_t r = 0; r < kAxes; ++r) {
    std::int64_t p50 = 0, p60 = 0;
    tone50_[r].Finish(&b.a50[r], &p50);
    tone60_[r].Finish(&b.a60[r], &p60);
    // The difference's variance less the tones: what is left is broadband noise; for white
    // noise of σ per sample the difference has 2σ².
    const std::int64_t var_q8 =
        (sum_d2_[r] * 256 - (sum_d_[r] * sum_d_[r] * 256) / n) / n - p50 - p60;
    b.sigma[r] = var_q8 <= 0 ? 0 : ISqrt64(static_cast<std::uint64_t>(var_q8) * 128);
    sum_d_[r] = 0;
    sum_d2_[r] = 0;
  }
  const bool use = pending_use_ && !block_moved_;
  const BlockResult previous = pending_;
  pending_ = b;
  pending_use_ = !block_moved_;
  block_pos_ = 0;
  block_moved_ = false;
  if (use) TakeBlock(previous);
}

void HealthWatch::TakeBlock(const BlockResult& b) {
  const std::size_t slot = blocks_seen_ % kToneBlocks;
  const std::size_t n = std::min<std::size_t>(blocks_seen_ + 1, kToneBlocks);
  for (std::size_t r = 0; r < kAxes; ++r) {
    block_ring_[0][r][slot] = Sat32(b.a50[r]);
    block_ring_[1][r][slot] = Sat32(b.a60[r]);
    block_ring_[2][r][slot] = Sat32(b.sigma[r]);
    a50_q8_[r] = health_int::Median(block_ring_[0][r], n);
    a60_q8_[r] = health_int::Median(block_ring_[1][r], n);
    sigma_q8_[r] = health_int::Median(block_ring_[2][r], n);
    if (commission_blocks_ > 0) sigma_ref_sum_q8_[r] += sigma_q8_[r];
  }
  ++blocks_seen_;
  if (commission_blocks_ > 0 && --commission_blocks_ == 0) {
    for (std::size_t r = 0; r < kAxes; ++r) {
      sigma_ref_q8_[r] = sigma_ref_sum_q8_[r] / kCommissionBlocks;
    }
  }
  if (blocks_seen_ < kToneBlocks) return;  // the medians need kToneBlocks blocks
  Judged(HealthCause::kMains50);
  Judged(HealthCause::kMains60);
  if (commission_blocks_ == 0) Judged(HealthCause::kNoiseFloor);
  bool mains50 = false, mains60 = false, noisy = false;
  std::int64_t worst50 = 0, worst60 = 0, worst_ratio = 0;
  WrenchLsb e50{}, e60{}, en{};
  for (std::size_t r = 0; r < kAxes; ++r) {
    // A tone counts above the absolute limit and above twice the RMS a tone bin reads on noise
    // alone (2σ/√N per block, averaged).
    const std::int64_t floor_q8 = (4 * sigma_q8_[r] * inv_sqrt_block_q16_) >> 16;
    const std::int64_t lim_q8 = std::int64_t{rated_[r]} * th_.mains_limit_bp * 256 / 10000;
    mains50 = mains50 || (a50_q8_[r] > lim_q8 && a50_q8_[r] > floor_q8);
    mains60 = mains60 || (a60_q8_[r] > lim_q8 && a60_q8_[r] > floor_q8);
    e50[r] = Sat32((a50_q8_[r] + 128) >> 8);
    e60[r] = Sat32((a60_q8_[r] + 128) >> 8);
    en[r] = Sat32((sigma_q8_[r] + 128) >> 8);
    const std::int64_t rated_q8 = std::int64_t{256} * rated_[r];
    worst50 = std::max(worst50, a50_q8_[r] * 10000 / rated_q8);
    worst60 = std::max(worst60, a60_q8_[r] * 10000 / rated_q8);
    if (commission_blocks_ == 0 && sigma_ref_q8_[r] > 0) {
      const std::int64_t ratio = sigma_q8_[r] * 100 / sigma_ref_q8_[r];
      if (ratio > worst_ratio) worst_ratio = ratio;
      noisy = noisy || sigma_q8_[r] * 10 > sigma_ref_q8_[r] * th_.noise_factor_d;
    }
  }
  report_.mains50_bp = Sat32(worst50);
  report_.mains60_bp = Sat32(worst60);
  report_.noise_ratio_pct = Sat32(worst_ratio);
  SetFinding(HealthCause::kMains50, mains50, e50);
  SetFinding(HealthCause::kMains60, mains60, e60);
  SetFinding(HealthCause::kNoiseFloor, noisy, en);
}

void HealthWatch::Publish(const HealthInput& in) {
  HealthReport& r = report_;
  r.findings = active_;
  if (samples_ % rate_ == 0) {  // the coverage, once a second: causes judged within the hour
    const std::uint64_t hour = std::uint64_t{3600} * rate_;
    std::uint16_t covered = 0;
    for (std::size_t i = 0; i < kHealthCauses; ++i) {
      if (judged_at_[i] != 0 && samples_ - judged_at_[i] < hour) covered |= 1u << i;
    }
    r.coverage = covered;
  }
  r.ring_ref_mhz = ring_ref_mhz_;
  r.tare_age_s = static_cast<std::uint32_t>(samples_ / rate_) - tare_sample_;
  // The counts change only when a cycle closes: copy them then, not every sample.
  if (cycles_changed_) {
    cycles_changed_ = false;
    for (std::size_t a = 0; a < kAxes; ++a) {
      r.cycles[a] = rainflow_[a].cycles();
      r.cycle_bins[a] = rainflow_[a].bins();
    }
  }
  r.slots = {};
  std::size_t k = 0;
  for (std::size_t i = 0; i < kHealthCauses && k < kHealthSlots; ++i) {
    if ((active_ & (1u << i)) == 0) continue;
    r.slots[k].cause = static_cast<HealthCause>(i + 1);
    r.slots[k].error_lsb = error_[i];
    ++k;
  }
  const bool thermal =
      (active_ & (1u << (static_cast<int>(HealthCause::kThermalZeroDrift) - 1))) != 0;
  const bool zero = (active_ & (1u << (static_cast<int>(HealthCause::kZeroDrift) - 1))) != 0;
  const bool shift = (active_ & (1u << (static_cast<int>(HealthCause::kOverloadShift) - 1))) != 0;
  r.retare_suggested = thermal || zero || shift;
  r.retare_reason = shift     ? HealthCause::kOverloadShift
                    : thermal ? HealthCause::kThermalZeroDrift
                              : (zero ? HealthCause::kZeroDrift : HealthCause::kNone);
  if ((in.status & (kStatusBridgeFault | kStatusAdcFault | kStatusCalInvalid)) != 0) {
    r.state = Ne107State::kFailure;
  } else if (in.tare_pending) {
    r.state = Ne107State::kCheckFunction;
  } else if ((in.status & (kStatusOverload | kStatusSaturated | kStatusTempRange)) != 0) {
    r.state = Ne107State::kOffSpecification;
  } else if (active_ != 0) {
    r.state = Ne107State::kMaintenanceRequired;
  } else {
    r.state = Ne107State::kNormal;
  }
}

}  // namespace ftstack::fw
