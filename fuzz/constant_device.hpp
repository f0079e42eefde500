// A device for harnesses: a converter that always has a sample, behind a started Device with a
// diagonal calibration in both slots and a rated range.
#pragma once

#include <cstdint>
#include <cstdlib>

#include "firmware/core.hpp"
#include "firmware/device.hpp"
#include "hal/adc.hpp"

namespace ftstack::fuzz {

/// A converter that always has a sample: six channels of fixed counts.
class ConstantAdc final : public ftstack::hal::Adc {
  ftstack::hal::Status DoConfigure(const ftstack::hal::AdcConfig& config) override {
    info_ = {config.channel_count, -(1 << 23), (1 << 23) - 1, 3906250, config.rate_hz, true};
    return ftstack::hal::Status::kOk;
  }
  ftstack::hal::Status DoWaitDataReady(std::uint32_t) override { return ftstack::hal::Status::kOk; }
  ftstack::hal::Status DoRead(ftstack::hal::AdcSample& out) override {
    out = ftstack::hal::AdcSample{};
    out.channel_count = info_.channel_count;
    for (std::size_t c = 0; c < info_.channel_count; ++c) {
      out.counts[c] = static_cast<std::int32_t>(1000 * (c + 1) + (n_++ & 7));
    }
    return ftstack::hal::Status::kOk;
  }
  ftstack::hal::AdcInfo DoInfo() const override { return info_; }
  ftstack::hal::AdcInfo info_{};
  std::uint32_t n_ = 0;
};

/// Starts `device` over its ConstantAdc with the harnesses' calibration and publishes three
/// samples; aborts if the firmware refuses (a harness without a device finds nothing).
inline void StartConstantDevice(fw::Device& device) {
  fw::DeviceConfig cfg;
  fw::FloatCalibration fc;
  fc.channel_count = 6;
  for (std::size_t i = 0; i < 6; ++i) fc.matrix[i][i] = 100.0;
  const hal::AdcInfo info{6, -(1 << 23), (1 << 23) - 1, 3906250, 1000, true};
  fw::LoadReport report;
  if (fw::LoadCalibration(fc, info, &cfg.slots[0].fixed, &report) != fw::LoadStatus::kOk) {
    std::abort();
  }
  cfg.slots[0].present = true;
  cfg.slots[1] = cfg.slots[0];
  cfg.adc.channel_count = 6;
  cfg.adc.rate_hz = 1000;
  cfg.rated_lsb = {200000, 200000, 400000, 1000000, 1000000, 800000};
  if (device.Start(cfg) != fw::DeviceStatus::kOk) std::abort();
  bool published = false;
  for (int i = 0; i < 3; ++i) (void)device.Step(&published);
}

}  // namespace ftstack::fuzz
