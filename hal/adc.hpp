// The ADC interface every bridge read-out backend implements: configuration, data-ready, raw
// counts.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ftstack::hal {

/// Largest number of bridge channels one ADC front end reads (1 ≤ N ≤ kMaxChannels).
inline constexpr std::size_t kMaxChannels = 8;

/// Result of a HAL call. Every backend documents which of these it returns.
enum class Status : std::uint8_t {
  kOk = 0,
  kTimeout,          ///< no data-ready within the requested timeout
  kReadError,        ///< bus transfer failed, frame CRC wrong, or implausible data
  kInvalidArgument,  ///< configuration outside the backend's limits
  kNotConfigured,    ///< WaitDataReady/Read called before a successful Configure
  kUnavailable,      ///< device absent (no gpiochip, no spidev node, no permission)
  kEndOfData,        ///< a finite source (recording replay) has no more samples
};

/// Short human-readable name of a status ("ok", "timeout", ...).
[[nodiscard]] constexpr const char* ToString(Status s) {
  switch (s) {
    case Status::kOk:
      return "ok";
    case Status::kTimeout:
      return "timeout";
    case Status::kReadError:
      return "read error";
    case Status::kInvalidArgument:
      return "invalid argument";
    case Status::kNotConfigured:
      return "not configured";
    case Status::kUnavailable:
      return "unavailable";
    case Status::kEndOfData:
      return "end of data";
  }
  return "unknown";
}

/// Per-channel flags of one sample (bit set).
enum ChannelFlag : std::uint8_t {
  kChannelSaturated = 1u << 0,  ///< within 1 % of a rail (set by Adc::Read for every backend)
  kChannelTimeout = 1u << 1,    ///< this channel's converter did not signal data-ready in time
  kChannelReadError = 1u << 2,  ///< transfer/CRC error or detected protocol violation
};

/// What a backend is asked to do. Backends reject unsupported values with kInvalidArgument.
struct AdcConfig {
  std::uint8_t channel_count = 6;  ///< number of bridges read, 1 … kMaxChannels
  std::uint16_t gain = 128;        ///< programmable-gain-amplifier gain (backend's allowed set)
  std::uint32_t rate_hz = 1000;    ///< output data rate of one complete sample (all channels), Hz
};

/// What a configured backend delivers. Counts are ratiometric: full_scale_nvv is the bridge output
/// (in nV/V, i.e. 1e-9 of the excitation voltage) that reads as max_counts, so
/// bridge_mvv = counts * full_scale_nvv / max_counts / 1e6.
struct AdcInfo {
  std::uint8_t channel_count = 0;
  std::int32_t min_counts = 0;      ///< negative rail, counts (e.g. -2^23 for a 24-bit ADC)
  std::int32_t max_counts = 0;      ///< positive rail, counts (e.g. 2^23 - 1)
  std::int64_t full_scale_nvv = 0;  ///< bridge input at max_counts, nV/V
  std::uint32_t rate_hz = 0;        ///< configured sample rate, Hz
  bool simulated = false;           ///< true for the simulated backend (status bit 7)
  /// Conversions per data-ready (a FIFO's watermark): WaitDataReady may wait until this many
  /// samples have converted, which Read then delivers one by one without waiting, each with its
  /// own conversion time. 1: one data-ready per conversion.
  std::uint16_t block_samples = 1;
  /// AdcSample::timestamp_us is on the caller's monotonic clock (since Configure). False for a
  /// converter on a virtual timeline (the unpaced simulator): its times say nothing about when
  /// a sample was due, so no lateness can be judged from them.
  bool clock_timestamps = true;
};

/// One simultaneous reading of all channels.
struct AdcSample {
  std::uint8_t channel_count = 0;
  std::array<std::int32_t, kMaxChannels> counts{};  ///< signed raw ADC value per channel, counts
  std::array<std::uint8_t, kMaxChannels> flags{};   ///< ChannelFlag bits per channel
  /// When this sample converted, µs since the backend was configured (on the caller's
  /// CLOCK_MONOTONIC unless AdcInfo::clock_timestamps is false): the converter's schedule for a
  /// simulated ADC, data-ready for a hardware driver. Never the time it was read.
  std::uint64_t timestamp_us = 0;
  std::int32_t temperature_mdegc = 0;  ///< sensor body temperature, m°C (valid if has_temperature)
  bool has_temperature = false;
};

/// True when `counts` lies within 1 % of the span of either rail.
[[nodiscard]] constexpr bool NearRail(std::int32_t counts, const AdcInfo& info) {
  const std::int64_t span = static_cast<std::int64_t>(info.max_counts) - info.min_counts;
  const std::int64_t margin = span / 200;  // 1 % of the half-span on each side
  return counts >= static_cast<std::int64_t>(info.max_counts) - margin ||
         counts <= static_cast<std::int64_t>(info.min_counts) + margin;
}

/// An ADC front end reading N bridge channels. Public calls are non-virtual and apply the rules
/// common to every backend; backends implement the private Do… hooks.
///
/// Threading: one thread owns an Adc. Calls never throw and never allocate after Configure.
class Adc {
 public:
  virtual ~Adc() = default;
  Adc() = default;
  Adc(const Adc&) = delete;
  Adc& operator=(const Adc&) = delete;

  /// Applies gain, rate and channel count. Returns kInvalidArgument for channel_count outside
  /// 1 … kMaxChannels or a value the backend cannot do; kUnavailable when the device is absent.
  [[nodiscard]] Status Configure(const AdcConfig& config) {
    if (config.channel_count < 1 || config.channel_count > kMaxChannels || config.rate_hz == 0) {
      return Status::kInvalidArgument;
    }
    return DoConfigure(config);
  }

  /// Blocks until a new sample is ready or timeout_us elapses (kTimeout). kEndOfData for a
  /// finished replay, kNotConfigured before Configure.
  [[nodiscard]] Status WaitDataReady(std::uint32_t timeout_us) {
    return DoWaitDataReady(timeout_us);
  }

  /// Reads the sample that became ready. Sets kChannelSaturated on every channel within 1 % of a
  /// rail. kReadError when the transfer failed (flags then say which channels).
  [[nodiscard]] Status Read(AdcSample& out) {
    const Status s = DoRead(out);
    const AdcInfo info = DoInfo();
    for (std::size_t i = 0; i < out.channel_count && i < kMaxChannels; ++i) {
      if (NearRail(out.counts[i], info)) out.flags[i] |= kChannelSaturated;
    }
    return s;
  }

  /// Scaling, rails and rate of the current configuration (zeros before Configure).
  [[nodiscard]] AdcInfo Info() const { return DoInfo(); }

 private:
  virtual Status DoConfigure(const AdcConfig& config) = 0;
  virtual Status DoWaitDataReady(std::uint32_t timeout_us) = 0;
  virtual Status DoRead(AdcSample& out) = 0;
  virtual AdcInfo DoInfo() const = 0;
};

}  // namespace ftstack::hal
