// The sampling step of the firmware main loop: ADC → core → published sample with sequence/time.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/core.hpp"
#include "hal/adc.hpp"

namespace ftstack::fw {

/// One published sample: everything a Modbus reply or a log row is made of.
struct PublishedSample {
  std::uint32_t sequence = 0;  ///< +1 per published sample, wraps
  /// When the sample converted, µs since the ADC was configured (the backend's timestamp; Device
  /// makes it strictly increasing), wraps every 2^32 µs.
  std::uint32_t timestamp_us = 0;
  std::uint16_t timestamp_wraps = 0;  ///< how often timestamp_us wrapped (bits 32–47 of the time)
  WrenchLsb wrench{};                 ///< mN and 10 µN·m
  std::uint8_t channel_count = 0;
  std::array<std::int32_t, hal::kMaxChannels> raw_counts{};  ///< counts
  std::int32_t temperature_mdegc = 0;                        ///< m°C, valid if has_temperature
  bool has_temperature = false;
  std::uint16_t status = 0;  ///< StatusBit set
  /// Bit r: wrench axis r is not a value (the calibration does not determine it; status bit
  /// 10). Sensor frame from Sampler; the frame of `wrench` once Device published it.
  std::uint8_t invalid_axes = 0;
};

/// Drives one ADC through the core. Call Step() in the sampling thread's loop.
class Sampler {
 public:
  Sampler(hal::Adc& adc, WrenchCore& core) : adc_(adc), core_(core) {}

  /// Configures the ADC. Must succeed before Step.
  [[nodiscard]] hal::Status Start(const hal::AdcConfig& config);

  /// Waits up to one sample period more than a block of the ADC (AdcInfo::block_samples) for data,
  /// reads and processes it, fills `out`. On kTimeout or kReadError `out` repeats the last wrench
  /// with kStatusAdcFault (and kStatusStale on timeout) set. kEndOfData when a replay ended.
  [[nodiscard]] hal::Status Step(PublishedSample& out);

  [[nodiscard]] const hal::AdcInfo& info() const { return info_; }
  /// The core's output for the last successful Step (unfiltered wrench, update flag).
  [[nodiscard]] const CoreOutput& core_output() const { return core_out_; }
  [[nodiscard]] std::uint32_t read_errors() const { return read_errors_; }
  [[nodiscard]] std::uint32_t timeouts() const { return timeouts_; }

 private:
  hal::Adc& adc_;
  WrenchCore& core_;
  hal::AdcInfo info_{};
  hal::AdcSample sample_{};
  CoreOutput core_out_{};
  PublishedSample last_{};
  std::uint32_t sequence_ = 0;
  std::uint32_t period_us_ = 1000;
  std::uint32_t block_samples_ = 1;
  std::uint32_t read_errors_ = 0;
  std::uint32_t timeouts_ = 0;
};

}  // namespace ftstack::fw
