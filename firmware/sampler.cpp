#include "firmware/sampler.hpp"

#include <algorithm>

namespace ftstack::fw {

hal::Status Sampler::Start(const hal::AdcConfig& config) {
  const hal::Status s = adc_.Configure(config);
  if (s != hal::Status::kOk) return s;
  info_ = adc_.Info();
  period_us_ = info_.rate_hz > 0 ? 1000000u / info_.rate_hz : 1000u;
  if (period_us_ == 0) period_us_ = 1;
  block_samples_ = info_.block_samples > 0 ? info_.block_samples : 1;
  return hal::Status::kOk;
}

hal::Status Sampler::Step(PublishedSample& out) {
  // A block's data-ready comes block_samples periods after the previous block's: one period of
  // slack on top, as for a single sample.
  const std::uint64_t timeout_us = (std::uint64_t{block_samples_} + 1u) * period_us_;
  hal::Status s = adc_.WaitDataReady(
      static_cast<std::uint32_t>(std::min<std::uint64_t>(timeout_us, 0xFFFFFFFFu)));
  if (s == hal::Status::kOk) s = adc_.Read(sample_);
  if (s == hal::Status::kEndOfData) return s;
  if (s != hal::Status::kOk) {
    if (s == hal::Status::kTimeout) {
      ++timeouts_;
    } else {
      ++read_errors_;
    }
    out = last_;
    out.status = static_cast<std::uint16_t>(out.status | kStatusAdcFault |
                                            (s == hal::Status::kTimeout ? kStatusStale : 0));
    return s;
  }
  core_.Process(sample_, info_.simulated, core_out_);
  PublishedSample p{};
  p.sequence = ++sequence_;
  p.timestamp_us = static_cast<std::uint32_t>(sample_.timestamp_us);
  p.timestamp_wraps = static_cast<std::uint16_t>(sample_.timestamp_us >> 32);
  p.wrench = core_out_.wrench;
  p.channel_count = sample_.channel_count;
  p.raw_counts = sample_.counts;
  p.has_temperature = sample_.has_temperature;
  p.temperature_mdegc = sample_.temperature_mdegc;
  p.status = core_out_.status;
  p.invalid_axes = core_.calibration().invalid_axes;
  last_ = p;
  out = p;
  return hal::Status::kOk;
}

}  // namespace ftstack::fw
