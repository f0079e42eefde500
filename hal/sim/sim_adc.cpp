#include "hal/sim/sim_adc.hpp"

#include <cmath>
#include <ctime>

namespace ftstack::hal::sim {
namespace {

std::int64_t MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

void SleepUntilNs(std::int64_t t_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1000000000LL);
  ts.tv_nsec = static_cast<long>(t_ns % 1000000000LL);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace

SimAdc::SimAdc(BridgeSignalSource& source, const SimAdcParams& params)
    : source_(source), params_(params), rng_(params.seed) {}

Status SimAdc::DoConfigure(const AdcConfig& config) {
  if (params_.resolution_bits < 8 || params_.resolution_bits > 31 || params_.reference_ratio <= 0 ||
      config.gain == 0 || config.channel_count != source_.channel_count() ||
      config.rate_hz > 1000000 ||
      (params_.required_gain != 0 && config.gain != params_.required_gain) ||
      (params_.required_rate_hz != 0 && config.rate_hz != params_.required_rate_hz) ||
      params_.block_samples < 1 || params_.block_samples > kMaxBlockSamples) {
    return Status::kInvalidArgument;
  }
  const std::int64_t half = std::int64_t{1} << (params_.resolution_bits - 1);
  info_.channel_count = config.channel_count;
  info_.max_counts = static_cast<std::int32_t>(half - 1);
  info_.min_counts = static_cast<std::int32_t>(-half);
  const double full_scale_mvv = 1000.0 * params_.reference_ratio / config.gain;
  info_.full_scale_nvv = std::llround(full_scale_mvv * 1e6);
  info_.rate_hz = config.rate_hz;
  info_.simulated = true;
  info_.block_samples = params_.realtime ? params_.block_samples : 1;
  info_.clock_timestamps = params_.realtime;
  counts_per_mvv_ = static_cast<double>(info_.max_counts) / full_scale_mvv;
  configured_ = true;
  ready_ = false;
  index_ = 0;
  start_ns_ = MonotonicNs();
  return Status::kOk;
}

Status SimAdc::DoWaitDataReady(std::uint32_t timeout_us) {
  if (!configured_) return Status::kNotConfigured;
  if (fault_ == SimFault::kNoDataReady) {
    if (params_.realtime) SleepUntilNs(MonotonicNs() + std::int64_t{timeout_us} * 1000);
    return Status::kTimeout;
  }
  if (params_.realtime) {
    // A converter with a FIFO: while converted samples wait in it, data-ready is already there;
    // an empty FIFO signals when the last sample of the block (samples n·B … n·B + B − 1)
    // holding the next one has converted.
    const std::int64_t now_ns = MonotonicNs();
    if (DueNs(index_) > now_ns) {
      const std::uint64_t block = info_.block_samples;
      const std::int64_t wake_ns = DueNs(index_ / block * block + block - 1);
      if (wake_ns > now_ns + std::int64_t{timeout_us} * 1000) {
        SleepUntilNs(now_ns + std::int64_t{timeout_us} * 1000);
        return Status::kTimeout;
      }
      SleepUntilNs(wake_ns);
    }
  }
  ready_ = true;
  return Status::kOk;
}

std::int64_t SimAdc::DueNs(std::uint64_t index) const {
  const double speed = params_.speed > 0 ? params_.speed : 1.0;
  return start_ns_ +
         static_cast<std::int64_t>(static_cast<double>(index) * 1e9 / (info_.rate_hz * speed));
}

Status SimAdc::DoRead(AdcSample& out) {
  if (!configured_) return Status::kNotConfigured;
  if (!ready_) return Status::kTimeout;
  ready_ = false;
  const std::uint8_t n = info_.channel_count;
  const double t_s = static_cast<double>(index_) / info_.rate_hz;
  const std::uint64_t timestamp_us =
      params_.realtime ? static_cast<std::uint64_t>(DueNs(index_) - start_ns_) / 1000u
                       : index_ * 1000000ULL / info_.rate_hz;
  ++index_;
  if (params_.stall_every != 0 && params_.stall_us != 0 && index_ % params_.stall_every == 0) {
    SleepUntilNs(MonotonicNs() + std::int64_t{params_.stall_us} * 1000);
  }
  if (fault_ == SimFault::kStuck && last_.channel_count == n) {
    out = last_;
    out.timestamp_us = timestamp_us;
    return Status::kOk;
  }
  std::array<double, kMaxChannels> mvv{};
  double temperature_c = NAN;
  if (!source_.Sample(t_s, mvv.data(), &temperature_c)) return Status::kEndOfData;
  out = AdcSample{};
  out.channel_count = n;
  out.timestamp_us = timestamp_us;
  for (std::uint8_t i = 0; i < n; ++i) {
    const double noisy_mvv = mvv[i] + params_.noise_rms_mvv * normal_(rng_);
    double counts = std::nearbyint(noisy_mvv * counts_per_mvv_);
    if (!(counts < info_.max_counts)) counts = info_.max_counts;  // also catches NaN
    if (counts < info_.min_counts) counts = info_.min_counts;
    out.counts[i] = static_cast<std::int32_t>(counts);
  }
  if (fault_ == SimFault::kOpenBridge && fault_channel_ < n) {
    out.counts[fault_channel_] = info_.max_counts;
  }
  if (params_.temperature && std::isfinite(temperature_c)) {
    out.has_temperature = true;
    out.temperature_mdegc = static_cast<std::int32_t>(std::lround(temperature_c * 1000.0));
  }
  last_ = out;
  if (fault_ == SimFault::kReadError) {
    for (std::uint8_t i = 0; i < n; ++i) out.flags[i] |= kChannelReadError;
    return Status::kReadError;
  }
  return Status::kOk;
}

}  // namespace ftstack::hal::sim
