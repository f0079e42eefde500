// A scripted ADC for firmware tests: returns the counts and status the test sets; stamps each
// sample at data-ready on the test's clock when it has one.
#pragma once

#include <array>
#include <cstdint>

#include "hal/adc.hpp"

namespace ftstack::test {

/// 24-bit ratiometric ADC, ±3.90625 mV/V, six channels; Read returns `counts` as set by the test.
class FakeAdc final : public hal::Adc {
 public:
  std::array<std::int32_t, hal::kMaxChannels> counts{};
  hal::Status next_status = hal::Status::kOk;  ///< what WaitDataReady returns
  std::uint64_t timestamp_us = 0;  ///< without a clock: the next stamp, then + one period per read
  std::int32_t temperature_mdegc = 20000;
  /// The test's clock (µs): with it a read is stamped when it happens, since Configure, as a
  /// hardware driver stamps at data-ready.
  std::uint64_t (*clock_us)() = nullptr;

 private:
  hal::Status DoConfigure(const hal::AdcConfig& config) override {
    info_.channel_count = config.channel_count;
    info_.min_counts = -(1 << 23);
    info_.max_counts = (1 << 23) - 1;
    info_.full_scale_nvv = 3906250;
    info_.rate_hz = config.rate_hz;
    info_.simulated = false;
    if (clock_us != nullptr) start_us_ = clock_us();
    return hal::Status::kOk;
  }
  hal::Status DoWaitDataReady(std::uint32_t) override { return next_status; }
  hal::Status DoRead(hal::AdcSample& out) override {
    out = hal::AdcSample{};
    out.channel_count = info_.channel_count;
    out.counts = counts;
    if (clock_us != nullptr) timestamp_us = clock_us() - start_us_;
    out.timestamp_us = timestamp_us;
    timestamp_us += 1000000u / info_.rate_hz;
    out.has_temperature = true;
    out.temperature_mdegc = temperature_mdegc;
    return hal::Status::kOk;
  }
  hal::AdcInfo DoInfo() const override { return info_; }
  hal::AdcInfo info_{};
  std::uint64_t start_us_ = 0;
};

}  // namespace ftstack::test
