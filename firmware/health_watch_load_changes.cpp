// The health watch's judgements after a load change: the mount's ringing and creep in holds.
#include <algorithm>

#include "firmware/health_int.hpp"
#include "firmware/health_watch.hpp"

namespace ftstack::fw {

using health_int::Abs;
using health_int::Median3;
using health_int::Sat32;

namespace {
constexpr std::int64_t kMinStepBp = 1000;  ///< creep: a load change of ≥ 10 % of rated
}  // namespace

void HealthWatch::UpdateRinging(const HealthInput& in) {
  if (refractory_ > 0) --refractory_;
  if (analysing_ < kAxes) {  // a slice of one axis of the finished capture per sample
    if (!ring_scan_.Advance(kRingSlice)) return;
    FinishAxis(analysing_);
    if (++analysing_ < kAxes) {
      StartAxis(analysing_);
    } else {
      FinishRinging();
    }
    return;
  }
  if (!capturing_) {
    // Not before a block has measured the tones the trigger allows for.
    if (refractory_ > 0 || blocks_seen_ == 0) return;
    bool jump = false;
    for (std::size_t r = 0; r < kAxes && !jump; ++r) {
      // Beyond the tracked tones' peaks: a steady tone is no transient.
      jump = Abs(std::int64_t{in.tared[r]} * 256 - fast_q8_[r]) >
             step_[r] * 256 + a50_q8_[r] + a60_q8_[r];
    }
    if (!jump) return;
    capturing_ = true;
    capture_pos_ = 0;
    stride_count_ = 0;
  }
  if (stride_count_++ % capture_stride_ != 0) return;
  for (std::size_t r = 0; r < kAxes; ++r) capture_[r][capture_pos_] = in.tared[r];
  if (++capture_pos_ < kRingCapture) return;
  capturing_ = false;
  refractory_ = static_cast<std::uint32_t>(kRingCapture) * capture_stride_;
  analysing_ = 0;  // the next samples analyse it, axis by axis, a slice per sample
  StartAxis(0);
}

void HealthWatch::StartAxis(std::size_t r) {
  // Hysteresis: 4σ of the noise (the commissioning's, or the current one before it is known)
  // plus the tracked 50 and 60 Hz peaks: a steady tone alone never confirms a crossing, or its
  // crossings would be read as the mount's ringing.
  const std::int64_t sigma = sigma_ref_q8_[r] > 0 ? sigma_ref_q8_[r] : sigma_q8_[r];
  ring_noise_h_ = Sat32(((4 * sigma) >> 8) + 1);
  // Only what stands above the bin's reading on noise alone (the mains rule's floor) is a tone.
  const std::int64_t floor_q8 = (4 * sigma_q8_[r] * inv_sqrt_block_q16_) >> 16;
  ring_tone_ = Sat32((std::max<std::int64_t>(a50_q8_[r] - floor_q8, 0) +
                      std::max<std::int64_t>(a60_q8_[r] - floor_q8, 0)) >>
                     8);
  ring_h_ = Sat32(std::int64_t{ring_noise_h_} + ring_tone_);
  ring_scan_.Start(capture_[r].data(), kRingCapture, rate_ / capture_stride_, ring_h_);
}

void HealthWatch::FinishAxis(std::size_t r) {
  ring_axis_[r] = ring_scan_.result();
  // A ringing well clear of the noise (8 noise bands) and of the tone (its peak counts three
  // times: a tone under half the ringing moves a crossing by at most 1/12 period): the count is
  // then clean.
  const std::int64_t clear = 8 * std::int64_t{ring_noise_h_} + 3 * std::int64_t{ring_tone_};
  if (ring_axis_[r].amplitude < clear) ring_axis_[r].freq_mhz = 0;
}

void HealthWatch::FinishRinging() {
  // The axis that moved most (share of rated) carries the frequency.
  std::size_t dom = 0;
  std::int64_t best = -1;
  WrenchLsb amplitude{};
  for (std::size_t r = 0; r < kAxes; ++r) {
    const std::int64_t share =
        Abs(std::int64_t{capture_[r][kRingCapture - 1]} - capture_[r][0]) * 10000 / rated_[r];
    if (share > best) {
      best = share;
      dom = r;
    }
    amplitude[r] = ring_axis_[r].freq_mhz > 0 ? ring_axis_[r].amplitude : 0;
  }
  const RingingResult& main = ring_axis_[dom];
  if (main.freq_mhz <= 0) return;
  report_.ring_mhz = main.freq_mhz;
  ring_last_mhz_[ring_measured_ % 3] = main.freq_mhz;
  ++ring_measured_;
  // A mode of the mount rings at one frequency after every step: three readings that scatter by
  // more than the shift to be found measured something else (the load's own swings), and neither
  // teach the reference nor judge it.
  const auto agree = [this](const std::array<std::int32_t, 3>& f) {
    const std::int64_t spread =
        std::int64_t{std::max({f[0], f[1], f[2]})} - std::min({f[0], f[1], f[2]});
    return spread * 1000 <= std::int64_t{Median3(f)} * th_.resonance_shift_pm;
  };
  if (ring_ref_mhz_ == 0) {
    ring_learn_mhz_[ring_learned_ % 3] = main.freq_mhz;
    ++ring_learned_;
    if (ring_learned_ >= 3 && agree(ring_learn_mhz_)) ring_ref_mhz_ = Median3(ring_learn_mhz_);
    return;
  }
  if (ring_measured_ < 3 || !agree(ring_last_mhz_)) return;
  Judged(HealthCause::kResonanceShift);
  const std::int64_t now = Median3(ring_last_mhz_);
  const bool shifted =
      Abs(now - ring_ref_mhz_) * 1000 > std::int64_t{ring_ref_mhz_} * th_.resonance_shift_pm;
  SetFinding(HealthCause::kResonanceShift, shifted, amplitude);
}

void HealthWatch::UpdateCreep(const HealthInput& in, bool moving) {
  switch (creep_phase_) {
    case CreepPhase::kIdle:
      if (!moving) return;
      for (std::size_t r = 0; r < kAxes; ++r) pre_level_[r] = slow_q8_[r] >> 8;
      creep_phase_ = CreepPhase::kMoving;
      return;
    case CreepPhase::kMoving:
      if (moving) return;
      creep_phase_ = CreepPhase::kSettling;
      creep_count_ = rate_ / 5;  // 0.2 s
      return;
    case CreepPhase::kSettling:
      if (moving) {
        creep_phase_ = CreepPhase::kMoving;
      } else if (--creep_count_ == 0) {
        creep_phase_ = CreepPhase::kHold;
        seg_sum_ = {};
        for (std::size_t r = 0; r < kAxes; ++r) {
          hold_max_[r] = hold_min_[r] = level_sum_[r];
        }
        retreat_up_ = {};
        retreat_down_ = {};
      }
      return;
    case CreepPhase::kHold:
      if (moving) {  // the hold ended early: this move is the next one judged
        for (std::size_t r = 0; r < kAxes; ++r) {
          pre_level_[r] = level_sum_[r] / static_cast<std::int64_t>(level_len_);
        }
        creep_phase_ = CreepPhase::kMoving;
        return;
      }
      {
        const std::size_t seg = creep_count_ / seg_len_;
        for (std::size_t r = 0; r < kAxes; ++r) seg_sum_[seg][r] += in.tared[r];
      }
      if (creep_count_ % block_ == 0) TrackHoldLevel();
      if (++creep_count_ == 3 * seg_len_) FinishCreep();
      return;
  }
}

void HealthWatch::TrackHoldLevel() {
  // In the ring's sum (level × level_len_): how far the 0.1 s level came back from its highest
  // and from its lowest so far in this hold.
  for (std::size_t r = 0; r < kAxes; ++r) {
    const std::int64_t v = level_sum_[r];
    hold_max_[r] = std::max(hold_max_[r], v);
    hold_min_[r] = std::min(hold_min_[r], v);
    retreat_down_[r] = std::max(retreat_down_[r], hold_max_[r] - v);
    retreat_up_[r] = std::max(retreat_up_[r], v - hold_min_[r]);
  }
}

void HealthWatch::FinishCreep() {
  creep_phase_ = CreepPhase::kIdle;
  const std::int64_t n = seg_len_;
  std::size_t dom = 0;
  std::int64_t best = -1;
  std::array<std::int64_t, kAxes> step{}, share{};
  std::array<std::array<std::int64_t, kAxes>, 3> m{};
  for (std::size_t r = 0; r < kAxes; ++r) {
    for (std::size_t k = 0; k < 3; ++k) m[k][r] = seg_sum_[k][r] / n;
    step[r] = m[0][r] - pre_level_[r];
    share[r] = Abs(step[r]) * 10000 / rated_[r];
    if (share[r] > best) {
      best = share[r];
      dom = r;
    }
  }
  if (best < kMinStepBp) return;  // too small a load change to judge creep on
  // The segment means carry noise σ/√n each (n = 20 blocks: 1/√n ≈ 1/(4·√block)); a change
  // must stand 6 such σ above it.
  const auto guard = [this](std::size_t r) {
    return ((6 * sigma_q8_[r] * inv_sqrt_block_q16_) >> 16) / (std::int64_t{4} * 256) + 1;
  };
  const std::int64_t d1 = m[1][dom] - m[0][dom];
  const std::int64_t d2 = m[2][dom] - m[1][dom];
  const std::int64_t seen = d1 + d2;
  // A first-order approach keeps the increments' sign and lets them decay (τ below ≈ 40 s); its
  // creep still to come is extrapolated. Otherwise what was seen is all there is.
  const bool decays = d1 != 0 && (d1 > 0) == (d2 > 0) && Abs(d2) * 20 < Abs(d1) * 19;
  const std::int64_t estimate = decays ? CreepRemaining(m[0][dom], m[1][dom], m[2][dom]) : seen;
  // A still hold without creep: its evidence counts against the findings so far.
  if (Abs(estimate) * 10000 <= Abs(step[dom]) * th_.creep_limit_bp || Abs(seen) <= guard(dom)) {
    report_.creep_bp = Sat32(estimate * 10000 / step[dom]);
    Judged(HealthCause::kCreep);
    creep_streak_ = 0;
    SetFinding(HealthCause::kCreep, false, {});
    return;
  }
  // A ramp, or a load change that starts or stops inside the hold, is the load moving: no
  // verdict either way.
  if (!decays) return;
  // A creep approaches its end monotonically: the 0.1 s level (sampled every 0.1 s) never comes
  // back against the creep's direction by more than its noise (6 σ of a 0.1 s mean) and a
  // quarter of what crept. A load that wanders under the moving gate (a contact force varying
  // within ±10 %) comes back by its own size: not still, no verdict.
  {
    const std::int64_t retreat = ((seen > 0 ? retreat_down_[dom] : retreat_up_[dom]) +
                                  static_cast<std::int64_t>(level_len_) / 2) /
                                 static_cast<std::int64_t>(level_len_);
    const std::int64_t level_noise = ((6 * sigma_q8_[dom] * inv_sqrt_block_q16_) >> 16) / 256 + 1;
    if (retreat > level_noise + Abs(seen) / 4) return;
  }
  // The load's own trend: axes that did not step (under a tenth of the main step's share) creep
  // by a tenth of its creep at most; more there is the load moving (a part re-oriented).
  const std::int64_t quiet_bp = Abs(seen) * 10000 / rated_[dom] / 2;
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (r == dom || share[r] * 10 >= best) continue;
    const std::int64_t moved = Abs(m[2][r] - m[0][r]);
    if (moved > guard(r) && moved * 10000 / rated_[r] > quiet_bp) return;
  }
  Judged(HealthCause::kCreep);
  WrenchLsb creep{};
  for (std::size_t r = 0; r < kAxes; ++r) {
    creep[r] = Sat32(CreepRemaining(m[0][r], m[1][r], m[2][r]));
  }
  report_.creep_bp = Sat32(std::int64_t{creep[dom]} * 10000 / step[dom]);
  const int sign = (seen > 0) == (step[dom] > 0) ? 1 : -1;
  const std::int64_t ratio_q16 = d2 * 65536 / d1;  // e^(−2 s/τ), in (0, 0.95)
  // τ within a factor 2 of the streak's: ln q within a factor 2, i.e. q² ≤ q' and q'² ≤ q.
  const bool agrees = creep_streak_ > 0 && sign == creep_sign_ &&
                      ratio_q16 * ratio_q16 <= creep_ratio_q16_ * 65536 &&
                      creep_ratio_q16_ * creep_ratio_q16_ <= ratio_q16 * 65536;
  creep_streak_ = agrees ? creep_streak_ + 1 : 1;
  if (!agrees) {  // the streak's first hold is what the others are compared with
    creep_sign_ = sign;
    creep_ratio_q16_ = ratio_q16;
  }
  if (creep_streak_ >= kCreepHolds) SetFinding(HealthCause::kCreep, true, creep);
}

}  // namespace ftstack::fw
