#include "firmware/core.hpp"

#include "firmware/fixed_point.hpp"

namespace ftstack::fw {

void WrenchCore::SetCalibration(const FixedCalibration& cal) {
  cal_ = cal;
  ClearTare();
  ResetFilter();
  last_valid_ = {};
}

bool WrenchCore::RequestTare(std::uint16_t samples) {
  if (samples < 1 || samples > kMaxTareSamples) return false;
  tare_sum_ = {};
  tare_total_ = samples;
  tare_remaining_ = samples;
  return true;
}

void WrenchCore::ClearTare() {
  tare_active_ = false;
  tare_remaining_ = 0;
  tare_counts_ = {};
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
  std::array<std::int64_t, kMaxChannels> x{};
  for (std::size_t c = 0; c < cal_.channel_count; ++c) {
    std::int32_t v = counts[c];
    if (v > cal_.max_counts) {
      v = cal_.max_counts;
      *saturated = true;
    } else if (v < cal_.min_counts) {
      v = cal_.min_counts;
      *saturated = true;
    }
    x[c] = static_cast<std::int64_t>(v) - (tare_active_ ? tare_counts_[c] : 0);
  }
  for (std::size_t r = 0; r < kAxes; ++r) {
    // The loader guarantees |acc| < 2^62 for every x between the rails.
    std::int64_t acc = tare_active_ ? 0 : cal_.bias[r];
    for (std::size_t c = 0; c < cal_.channel_count; ++c) acc += cal_.coef[r][c] * x[c];
    y[r] = SatToI32(RoundShift(acc, cal_.shift[r]), saturated);
  }
}

void WrenchCore::Process(const hal::AdcSample& in, bool simulated, CoreOutput& out) {
  out.status = simulated ? kStatusSimulated : 0;
  out.arithmetic_saturated = false;
  out.updated = false;
  const std::size_t n = in.channel_count;

  // Fault detection on the raw counts.
  bool any_saturated = false;
  bool any_error = false;
  bool bridge_fault = false;
  bool all_same = n > 0;
  for (std::size_t c = 0; c < n && c < kMaxChannels; ++c) {
    const std::int32_t v = in.counts[c];
    if ((in.flags[c] & hal::kChannelSaturated) != 0) any_saturated = true;
    if ((in.flags[c] & (hal::kChannelReadError | hal::kChannelTimeout)) != 0) any_error = true;
    if (v != last_counts_[c]) all_same = false;
    const bool at_rail = cal_.valid && (v >= cal_.max_counts || v <= cal_.min_counts);
    rail_run_[c] = at_rail ? static_cast<std::uint16_t>(rail_run_[c] < 0xFFFF ? rail_run_[c] + 1
                                                                              : rail_run_[c])
                           : 0;
    if (limits_.rail_samples > 0 && rail_run_[c] >= limits_.rail_samples) bridge_fault = true;
    last_counts_[c] = v;
  }
  same_count_run_ = all_same ? static_cast<std::uint16_t>(
                                   same_count_run_ < 0xFFFF ? same_count_run_ + 1 : same_count_run_)
                             : 0;
  if (any_saturated) out.status |= kStatusSaturated;
  if (bridge_fault) out.status |= kStatusBridgeFault;
  if (any_error || (limits_.stuck_samples > 0 && same_count_run_ >= limits_.stuck_samples)) {
    out.status |= kStatusAdcFault;
  }

  if (!cal_.valid || n != cal_.channel_count) {
    out.status |= kStatusCalInvalid;
    out.wrench = {};
    out.unfiltered = {};
    return;
  }

  const bool usable = !any_saturated && !any_error && !bridge_fault;
  // Tare accumulates only on usable samples.
  if (usable && tare_remaining_ > 0) {
    for (std::size_t c = 0; c < n; ++c) tare_sum_[c] += in.counts[c];
    if (--tare_remaining_ == 0) {
      for (std::size_t c = 0; c < n; ++c) {
        tare_counts_[c] = static_cast<std::int32_t>(RoundDiv(tare_sum_[c], tare_total_));
      }
      tare_active_ = true;
      ResetFilter();
    }
  }
  if (tare_active_) out.status |= kStatusTareActive;

  if (!usable) {  // hold the last valid wrench
    out.wrench = last_valid_;
    return;
  }

  WrenchLsb y{};
  Apply(in.counts, y, &out.arithmetic_saturated);
  out.unfiltered = y;

  // Moving average over the last filter_length_ samples (shorter while filling).
  auto& slot = filter_ring_[filter_pos_];
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (filter_fill_ == filter_length_) filter_sum_[r] -= slot[r];
    filter_sum_[r] += y[r];
    slot[r] = y[r];
  }
  if (filter_fill_ < filter_length_) ++filter_fill_;
  filter_pos_ = static_cast<std::uint16_t>((filter_pos_ + 1) % filter_length_);
  if (filter_fill_ == 1) {
    out.wrench = y;  // no averaging: skip the divisions
  } else {
    for (std::size_t r = 0; r < kAxes; ++r) {
      out.wrench[r] = SatToI32(RoundDiv(filter_sum_[r], filter_fill_), &out.arithmetic_saturated);
    }
  }
  last_valid_ = out.wrench;
  out.updated = true;
}

}  // namespace ftstack::fw
