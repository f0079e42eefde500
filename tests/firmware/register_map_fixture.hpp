// A Device with a scripted ADC and a diagonal calibration behind a RegisterMap (register map
// tests).
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

#include "firmware/register_map.hpp"
#include "tests/firmware/fake_adc.hpp"

namespace ftstack::fw::maptest {

inline std::uint64_t g_now_us = 1000000;
inline std::uint64_t FakeClock() { return g_now_us; }

/// Rated range of the test device, LSB (mN and 10 µN·m): Fx, Fy 200 N, Fz 400 N, Mx, My 10 N·m, Mz
/// 8 N·m.
inline constexpr WrenchLsb kRatedLsb = {200000, 200000, 400000, 1000000, 1000000, 800000};
/// Diagonal calibration: N or N·m per mV/V, per axis.
inline constexpr std::array<double, 6> kGain = {100.0, 100.0, 200.0, 5.0, 5.0, 4.0};
/// The fake ADC's resolution: ±3.90625 mV/V over 24 bits.
inline constexpr double kMvvPerCount = 3.90625 / 8388607.0;

class RegisterMapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    g_now_us = 1000000;
    adc_.counts = {};
    FloatCalibration fc;
    fc.channel_count = 6;
    for (std::size_t i = 0; i < 6; ++i) fc.matrix[i][i] = kGain[i];
    hal::AdcInfo info{6, -(1 << 23), (1 << 23) - 1, 3906250, 1000, false};
    ASSERT_EQ(LoadCalibration(fc, info, &cfg_.slots[0].fixed, &report_), LoadStatus::kOk);
    cfg_.slots[0].crc32 = 0xCAFEF00Du;
    cfg_.slots[0].present = true;
    cfg_.adc.channel_count = 6;
    cfg_.adc.rate_hz = 1000;
    cfg_.rated_lsb = kRatedLsb;
    cfg_.tare_samples = 4;
    cfg_.clock_us = &FakeClock;
    adc_.clock_us = &FakeClock;
  }
  void StartDevice() {
    ASSERT_EQ(device_.Start(cfg_), DeviceStatus::kOk);
    map_ = std::make_unique<RegisterMap>(device_);
  }
  void Step(int n = 1) {
    for (int i = 0; i < n; ++i) {
      bool published = false;
      ASSERT_EQ(device_.Step(&published), hal::Status::kOk);
      g_now_us += 1000;
    }
  }
  std::array<std::uint16_t, kInputRegisterCount> Input() {
    std::array<std::uint16_t, kInputRegisterCount> r{};
    EXPECT_EQ(map_->ReadInput(0, kInputRegisterCount, r.data()), ModbusException::kNone);
    return r;
  }
  std::uint16_t Holding(std::uint16_t addr) {
    std::uint16_t v = 0xDEAD;
    EXPECT_EQ(map_->ReadHolding(addr, 1, &v), ModbusException::kNone);
    return v;
  }
  ModbusException Write(std::uint16_t addr, std::initializer_list<std::uint16_t> values) {
    std::vector<std::uint16_t> v(values);
    return map_->WriteHolding(addr, v.data(), static_cast<std::uint16_t>(v.size()));
  }
  ModbusException WriteFloats(std::uint16_t addr, std::initializer_list<float> values) {
    std::vector<std::uint16_t> v(values.size() * 2);
    std::size_t i = 0;
    for (float f : values) PackFloat32(f, &v[2 * i++]);
    return map_->WriteHolding(addr, v.data(), static_cast<std::uint16_t>(v.size()));
  }
  /// The wrench in SI a count vector produces through the diagonal test calibration.
  static double ExpectedSi(std::size_t axis, std::int32_t counts) {
    return kGain[axis] * counts * kMvvPerCount;
  }

  ftstack::test::FakeAdc adc_;
  WrenchCore core_;
  Device device_{adc_, core_};
  DeviceConfig cfg_;
  LoadReport report_;
  std::unique_ptr<RegisterMap> map_;
};

}  // namespace ftstack::fw::maptest
