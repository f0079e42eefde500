// The simulated ADC converts mV/V to counts exactly as a ratiometric 24-bit converter would.
#include <gtest/gtest.h>

#include <cmath>
#include <ctime>
#include <vector>

#include "hal/sim/sim_adc.hpp"

namespace ftstack::hal::sim {
namespace {

class RampSource final : public BridgeSignalSource {
 public:
  explicit RampSource(std::uint8_t n, double slope_mvv_per_s = 0.0, double end_s = 1e9)
      : n_(n), slope_(slope_mvv_per_s), end_s_(end_s) {}
  std::uint8_t channel_count() const override { return n_; }
  bool Sample(double t_s, double* mvv, double* temperature_c) override {
    if (t_s > end_s_) return false;
    for (std::uint8_t i = 0; i < n_; ++i) mvv[i] = value[i] + slope_ * t_s;
    *temperature_c = 25.5;
    return true;
  }
  std::array<double, kMaxChannels> value{};

 private:
  std::uint8_t n_;
  double slope_;
  double end_s_;
};

SimAdcParams Quiet() {
  SimAdcParams p;
  p.noise_rms_mvv = 0.0;
  return p;
}

TEST(SimAdc, QuantisesRatiometricallyAndClipsAtTheRails) {
  RampSource src(4);
  src.value = {1.0, -2.5, 3.95, -4.2};  // the last two are beyond ±3.90625 mV/V
  SimAdc adc(src, Quiet());
  ASSERT_EQ(adc.Configure(AdcConfig{4, 128, 1000}), Status::kOk);
  const AdcInfo info = adc.Info();
  EXPECT_EQ(info.max_counts, 8388607);
  EXPECT_EQ(info.min_counts, -8388608);
  EXPECT_EQ(info.full_scale_nvv, 3906250);  // 0.5 / 128 of the excitation
  EXPECT_TRUE(info.simulated);
  ASSERT_EQ(adc.WaitDataReady(1000), Status::kOk);
  AdcSample s{};
  ASSERT_EQ(adc.Read(s), Status::kOk);
  const double cpm = 8388607.0 / 3.90625;
  EXPECT_EQ(s.counts[0], std::lround(1.0 * cpm));
  EXPECT_EQ(s.counts[1], std::lround(-2.5 * cpm));
  EXPECT_EQ(s.counts[2], 8388607);
  EXPECT_EQ(s.counts[3], -8388608);
  EXPECT_EQ(s.flags[0], 0);
  EXPECT_TRUE(s.flags[2] & kChannelSaturated);
  EXPECT_TRUE(s.flags[3] & kChannelSaturated);
  EXPECT_TRUE(s.has_temperature);
  EXPECT_EQ(s.temperature_mdegc, 25500);
}

TEST(SimAdc, AConverterWithoutATemperatureInputReportsNone) {
  RampSource src(2);  // the source gives 25.5 °C
  SimAdcParams p = Quiet();
  p.temperature = false;
  SimAdc adc(src, p);
  ASSERT_EQ(adc.Configure(AdcConfig{2, 128, 1000}), Status::kOk);
  ASSERT_EQ(adc.WaitDataReady(1000), Status::kOk);
  AdcSample s{};
  ASSERT_EQ(adc.Read(s), Status::kOk);
  EXPECT_FALSE(s.has_temperature);
  EXPECT_EQ(s.temperature_mdegc, 0);
}

TEST(SimAdc, GainScalesFullScale) {
  RampSource src(1);
  src.value[0] = 10.0;
  SimAdc adc(src, Quiet());
  ASSERT_EQ(adc.Configure(AdcConfig{1, 32, 100}), Status::kOk);
  EXPECT_EQ(adc.Info().full_scale_nvv, 15625000);  // 0.5/32 → 15.625 mV/V
  ASSERT_EQ(adc.WaitDataReady(0), Status::kOk);
  AdcSample s{};
  ASSERT_EQ(adc.Read(s), Status::kOk);
  EXPECT_EQ(s.counts[0], std::lround(10.0 * 8388607.0 / 15.625));
}

TEST(SimAdc, NoiseHasRequestedRmsAndIsDeterministicPerSeed) {
  RampSource src(2);
  SimAdcParams p;
  p.noise_rms_mvv = 2e-4;
  p.seed = 42;
  SimAdc a(src, p);
  SimAdc b(src, p);
  p.seed = 43;
  SimAdc c(src, p);
  for (SimAdc* adc : {&a, &b, &c}) ASSERT_EQ(adc->Configure(AdcConfig{2, 128, 1000}), Status::kOk);
  const double cpm = 8388607.0 / 3.90625;
  const int n = 20000;
  double sum2 = 0;
  int differ = 0;
  for (int i = 0; i < n; ++i) {
    AdcSample sa{}, sb{}, sc{};
    ASSERT_EQ(a.WaitDataReady(0), Status::kOk);
    ASSERT_EQ(a.Read(sa), Status::kOk);
    ASSERT_EQ(b.WaitDataReady(0), Status::kOk);
    ASSERT_EQ(b.Read(sb), Status::kOk);
    ASSERT_EQ(c.WaitDataReady(0), Status::kOk);
    ASSERT_EQ(c.Read(sc), Status::kOk);
    ASSERT_EQ(sa.counts, sb.counts);
    differ += sa.counts[0] != sc.counts[0];
    sum2 += static_cast<double>(sa.counts[0]) * sa.counts[0];
    EXPECT_EQ(sa.timestamp_us, static_cast<std::uint64_t>(i) * 1000);
  }
  // RMS of n Gaussian samples (plus 1/12 count² quantisation): relative s.e. ≈ 1/√(2n) = 0.5 %.
  const double expected = std::sqrt(std::pow(2e-4 * cpm, 2) + 1.0 / 12);
  EXPECT_NEAR(std::sqrt(sum2 / n), expected, 4 * expected / std::sqrt(2.0 * n));
  EXPECT_GT(differ, n * 9 / 10);
}

TEST(SimAdc, FaultsAndLifecycle) {
  RampSource src(3, 0.0, 0.0105);
  SimAdc adc(src, Quiet());
  AdcSample s{};
  EXPECT_EQ(adc.WaitDataReady(0), Status::kNotConfigured);
  EXPECT_EQ(adc.Configure(AdcConfig{0, 128, 1000}), Status::kInvalidArgument);
  EXPECT_EQ(adc.Configure(AdcConfig{9, 128, 1000}), Status::kInvalidArgument);
  EXPECT_EQ(adc.Configure(AdcConfig{2, 128, 1000}), Status::kInvalidArgument);  // source has 3
  ASSERT_EQ(adc.Configure(AdcConfig{3, 128, 1000}), Status::kOk);
  EXPECT_EQ(adc.Read(s), Status::kTimeout);  // no data-ready waited for
  adc.SetFault(SimFault::kNoDataReady);
  EXPECT_EQ(adc.WaitDataReady(100), Status::kTimeout);
  adc.SetFault(SimFault::kOpenBridge, 1);
  ASSERT_EQ(adc.WaitDataReady(0), Status::kOk);
  ASSERT_EQ(adc.Read(s), Status::kOk);
  EXPECT_EQ(s.counts[1], 8388607);
  EXPECT_TRUE(s.flags[1] & kChannelSaturated);
  adc.SetFault(SimFault::kReadError);
  ASSERT_EQ(adc.WaitDataReady(0), Status::kOk);
  EXPECT_EQ(adc.Read(s), Status::kReadError);
  EXPECT_TRUE(s.flags[0] & kChannelReadError);
  adc.SetFault(SimFault::kNone);
  // The source ends after 10.5 ms: samples 0…10 exist, sample 11 is end of data.
  Status st = Status::kOk;
  int read = 0;
  while (st == Status::kOk && read < 100) {
    ASSERT_EQ(adc.WaitDataReady(0), Status::kOk);
    st = adc.Read(s);
    ++read;
  }
  EXPECT_EQ(st, Status::kEndOfData);
  EXPECT_EQ(adc.sample_index(), 12u);
}

std::int64_t NowUs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

TEST(SimAdc, PacedBlocksDeliverEverySampleAfterItConvertedWithItsOwnConversionTime) {
  // 8 kHz in blocks of 8: data-ready for a block comes once its last sample has converted, and
  // every sample carries its own conversion time (k × 125 µs), not the time it was read.
  RampSource src(2, 1.0);
  SimAdcParams p = Quiet();
  p.realtime = true;
  p.block_samples = 8;
  SimAdc adc(src, p);
  const std::int64_t before_us = NowUs();  // the ADC's time origin is at or after this
  ASSERT_EQ(adc.Configure(AdcConfig{2, 128, 8000}), Status::kOk);
  EXPECT_EQ(adc.Info().block_samples, 8);
  AdcSample s{};
  for (std::uint64_t k = 0; k < 400; ++k) {
    const std::int64_t asked_us = NowUs() - before_us;
    ASSERT_EQ(adc.WaitDataReady(9 * 125), Status::kOk) << "sample " << k;
    const std::int64_t ready_us = NowUs() - before_us;
    ASSERT_EQ(adc.Read(s), Status::kOk);
    EXPECT_EQ(s.timestamp_us, k * 125) << "sample " << k;
    // Never delivered before it converted; a block's first sample, asked for before it
    // converted, waits for the block's last (one asked for later is in the FIFO already).
    const std::uint64_t block_end_us = (k / 8 * 8 + 7) * 125;
    if (k % 8 == 0 && asked_us < static_cast<std::int64_t>(k * 125)) {
      EXPECT_GE(ready_us, static_cast<std::int64_t>(block_end_us)) << "sample " << k;
    }
    EXPECT_GE(ready_us, static_cast<std::int64_t>(s.timestamp_us)) << "sample " << k;
  }
  // The signal is sampled at the conversion instant: the ramp's 1 mV/V per s at k × 125 µs.
  const double cpm = adc.counts_per_mvv();
  EXPECT_NEAR(s.counts[0], std::nearbyint(399 * 125e-6 * cpm), 1.0);
  SimAdcParams bad = Quiet();
  bad.block_samples = 0;
  SimAdc zero(src, bad);
  EXPECT_EQ(zero.Configure(AdcConfig{2, 128, 8000}), Status::kInvalidArgument);
}

TEST(AdcInterface, NearRailIsOnePercentOfTheHalfSpan) {
  AdcInfo info;
  info.max_counts = 8388607;
  info.min_counts = -8388608;
  const std::int32_t margin = 16777215 / 200;
  EXPECT_TRUE(NearRail(8388607 - margin, info));
  EXPECT_FALSE(NearRail(8388607 - margin - 1, info));
  EXPECT_TRUE(NearRail(-8388608 + margin, info));
  EXPECT_FALSE(NearRail(-8388608 + margin + 1, info));
  EXPECT_FALSE(NearRail(0, info));
}

}  // namespace
}  // namespace ftstack::hal::sim
