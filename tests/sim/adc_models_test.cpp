// ADC models against their datasheets and the simulated ADC's counts: noise, span, clipping, rates.
#include <gtest/gtest.h>

#include <cmath>

#include "hal/sim/sim_adc.hpp"
#include "sim/adc_models.hpp"

namespace ftstack::sim {
namespace {

class ConstantBridges final : public hal::sim::BridgeSignalSource {
 public:
  ConstantBridges(std::uint8_t n, double mvv) : n_(n), mvv_(mvv) {}
  [[nodiscard]] std::uint8_t channel_count() const override { return n_; }
  [[nodiscard]] bool Sample(double, double* b, double* t) override {
    for (int i = 0; i < n_; ++i) b[i] = mvv_;
    *t = NAN;
    return true;
  }

 private:
  std::uint8_t n_;
  double mvv_;
};

hal::AdcConfig Config(std::uint8_t channels, std::uint16_t gain, std::uint32_t rate_hz) {
  hal::AdcConfig cfg;
  cfg.channel_count = channels;
  cfg.gain = gain;
  cfg.rate_hz = rate_hz;
  return cfg;
}

TEST(Hx711, DatasheetNoiseAndInputSpan) {
  EXPECT_DOUBLE_EQ(Hx711NoiseUv(128, 10), 0.050);
  EXPECT_DOUBLE_EQ(Hx711NoiseUv(128, 80), 0.090);
  EXPECT_DOUBLE_EQ(Hx711NoiseUv(32, 10), 0.200);  // modelled: output-referred noise kept
  EXPECT_THROW((void)Hx711NoiseUv(16, 10), std::invalid_argument);
  EXPECT_THROW((void)Hx711NoiseUv(128, 20), std::invalid_argument);
  AdcSpec s;
  s.chip = AdcChip::kHx711;
  s.gain = 128;
  s.rate_hz = 10;
  s.excitation_v = 5.0;
  const AdcOperatingPoint op = MakeAdcOperatingPoint(s);
  // ±0.5·AVDD/gain: ±20 mV at AVDD 5 V, i.e. ±3.90625 mV/V (datasheet "full-scale input").
  EXPECT_DOUBLE_EQ(op.full_scale_mvv, 3.90625);
  EXPECT_DOUBLE_EQ(op.params.noise_rms_mvv, 0.050e-3 / 5.0);
  EXPECT_EQ(op.params.resolution_bits, 24);
}

TEST(Ads131m0x, DatasheetNoiseTableAndInterpolation) {
  EXPECT_DOUBLE_EQ(Ads131m0xNoiseUv(128, 1000), 0.77);
  EXPECT_DOUBLE_EQ(Ads131m0xNoiseUv(128, 4000), 1.20);
  EXPECT_DOUBLE_EQ(Ads131m0xNoiseUv(1, 250), 1.90);
  // Between table rows: log–log, so at the geometric mean of the rates, the geometric mean noise.
  EXPECT_NEAR(Ads131m0xNoiseUv(128, std::sqrt(1000.0 * 2000.0)), std::sqrt(0.77 * 1.00), 1e-12);
  EXPECT_THROW((void)Ads131m0xNoiseUv(64, 1000), std::invalid_argument);
  EXPECT_THROW((void)Ads131m0xNoiseUv(128, 100), std::invalid_argument);
  AdcSpec s;  // defaults: ADS131M0x, gain 128, 1 kSPS, 3.3 V excitation, 1.2 V reference
  const AdcOperatingPoint op = MakeAdcOperatingPoint(s);
  EXPECT_NEAR(op.full_scale_mvv, 1000 * 1.2 / 128 / 3.3, 1e-12);  // ±1.2 V/gain
  EXPECT_NEAR(op.params.noise_rms_mvv, 0.77e-3 / 3.3, 1e-15);
  s.global_chop = true;  // datasheet: noise improves by √2 in global-chop mode
  EXPECT_NEAR(MakeAdcOperatingPoint(s).params.noise_rms_mvv, 0.77e-3 / 3.3 / std::sqrt(2.0), 1e-15);
}

// The simulated ADC at an HX711 operating point: the spread of the counts is the datasheet noise
// (plus one count of uniform quantisation), and inputs past the span clip at the rails.
TEST(SimAdcChain, Hx711CountsCarryTheModelledNoise) {
  AdcSpec s;
  s.chip = AdcChip::kHx711;
  s.rate_hz = 80;
  s.excitation_v = 5.0;
  AdcOperatingPoint op = MakeAdcOperatingPoint(s);
  op.params.seed = 7;
  ConstantBridges src(2, 0.5);
  hal::sim::SimAdc adc(src, op.params);
  ASSERT_EQ(adc.Configure(Config(2, 128, 80)), hal::Status::kOk);
  const int n = 20000;
  double sum = 0;
  double sum2 = 0;
  for (int i = 0; i < n; ++i) {
    hal::AdcSample smp;
    ASSERT_EQ(adc.WaitDataReady(0), hal::Status::kOk);
    ASSERT_EQ(adc.Read(smp), hal::Status::kOk);
    sum += smp.counts[0];
    sum2 += static_cast<double>(smp.counts[0]) * smp.counts[0];
  }
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  const double cpm = adc.counts_per_mvv();
  EXPECT_NEAR(cpm, 8388607 / 3.90625, 1e-6);
  const double expect_sd = std::sqrt(std::pow(op.params.noise_rms_mvv * cpm, 2) + 1.0 / 12.0);
  // Standard error of a standard deviation from n Gaussian samples: sd/√(2n); allow 5 of them.
  EXPECT_NEAR(sd, expect_sd, 5 * expect_sd / std::sqrt(2.0 * n));
  EXPECT_NEAR(mean, 0.5 * cpm, 5 * expect_sd / std::sqrt(n));
}

TEST(SimAdcChain, Ads131m0xClipsAtTheRailsAndRejectsOtherOperatingPoints) {
  AdcOperatingPoint op = MakeAdcOperatingPoint(AdcSpec{});
  ConstantBridges over(1, 1.5 * op.full_scale_mvv);
  hal::sim::SimAdc adc(over, op.params);
  hal::AdcConfig cfg = Config(1, 128, 1000);
  ASSERT_EQ(adc.Configure(cfg), hal::Status::kOk);
  hal::AdcSample smp;
  ASSERT_EQ(adc.WaitDataReady(0), hal::Status::kOk);
  ASSERT_EQ(adc.Read(smp), hal::Status::kOk);
  EXPECT_EQ(smp.counts[0], (1 << 23) - 1);
  EXPECT_TRUE(smp.flags[0] & hal::kChannelSaturated);
  // The noise figure belongs to gain 128 at 1 kSPS: another gain or rate is refused.
  cfg.rate_hz = 2000;
  EXPECT_EQ(adc.Configure(cfg), hal::Status::kInvalidArgument);
  cfg.rate_hz = 1000;
  cfg.gain = 64;
  EXPECT_EQ(adc.Configure(cfg), hal::Status::kInvalidArgument);
}

}  // namespace
}  // namespace ftstack::sim
