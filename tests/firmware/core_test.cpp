// Behaviour of the core around the matrix: tare, moving average, hold on saturation, fault bits.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <random>

#include "firmware/core.hpp"

namespace ftstack::fw {
namespace {

hal::AdcInfo Adc24() {
  hal::AdcInfo a;
  a.channel_count = 6;
  a.max_counts = (1 << 23) - 1;
  a.min_counts = -(1 << 23);
  a.full_scale_nvv = 3906250;
  a.rate_hz = 1000;
  return a;
}

FixedCalibration DiagonalCal(double n_per_mvv, double bias_n = 0.0) {
  FloatCalibration cal{};
  cal.channel_count = 6;
  for (std::size_t r = 0; r < kAxes; ++r) {
    cal.matrix[r][r] = r < 3 ? n_per_mvv : n_per_mvv / 20;
    cal.bias[r] = bias_n;
  }
  FixedCalibration fixed{};
  EXPECT_EQ(LoadCalibration(cal, Adc24(), &fixed, nullptr), LoadStatus::kOk);
  return fixed;
}

hal::AdcSample Sample(std::int32_t base, std::int32_t step = 0) {
  hal::AdcSample s{};
  s.channel_count = 6;
  for (std::size_t c = 0; c < 6; ++c) s.counts[c] = base + static_cast<std::int32_t>(c) * step;
  return s;
}

TEST(Core, TareZeroesTheCurrentLoadAndClearTareRestoresIt) {
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0, 1.5));
  core.SetLimits(CoreLimits{0, 0});
  CoreOutput out{};
  core.Process(Sample(200000, 1000), false, out);
  ASSERT_TRUE(out.updated);
  EXPECT_NE(out.wrench[0], 0);
  const WrenchLsb loaded = out.wrench;
  ASSERT_TRUE(core.RequestTare(8));
  // Noisy samples around the same load: the tare is their mean.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 50.0);
  std::array<double, 6> sum{};
  for (int i = 0; i < 8; ++i) {
    hal::AdcSample s = Sample(200000, 1000);
    for (std::size_t c = 0; c < 6; ++c) {
      s.counts[c] += static_cast<std::int32_t>(std::lround(noise(rng)));
      sum[c] += s.counts[c];
    }
    core.Process(s, false, out);
  }
  EXPECT_TRUE(core.tare_active());
  EXPECT_TRUE(out.status & kStatusTareActive);
  // A sample equal to the tare mean reads zero (±1 LSB from rounding of the tare).
  hal::AdcSample at_mean = Sample(0);
  for (std::size_t c = 0; c < 6; ++c)
    at_mean.counts[c] = static_cast<std::int32_t>(std::lround(sum[c] / 8));
  core.Process(at_mean, false, out);
  for (std::size_t r = 0; r < kAxes; ++r) EXPECT_LE(std::abs(out.unfiltered[r]), 1) << r;
  core.ClearTare();
  core.Process(Sample(200000, 1000), false, out);
  EXPECT_EQ(out.unfiltered, loaded);
  EXPECT_FALSE(out.status & kStatusTareActive);
  EXPECT_FALSE(core.RequestTare(0));
  EXPECT_FALSE(core.RequestTare(kMaxTareSamples + 1));
}

TEST(Core, MovingAverageMatchesDoubleReference) {
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0));
  core.SetLimits(CoreLimits{0, 0});
  ASSERT_TRUE(core.SetFilterLength(16));
  EXPECT_FALSE(core.SetFilterLength(0));
  EXPECT_FALSE(core.SetFilterLength(kMaxFilterLength + 1));
  EXPECT_EQ(core.filter_length(), 16);
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::int32_t> d(-3000000, 3000000);
  std::deque<WrenchLsb> window;
  for (int i = 0; i < 300; ++i) {
    hal::AdcSample s = Sample(0);
    for (std::size_t c = 0; c < 6; ++c) s.counts[c] = d(rng);
    CoreOutput out{};
    core.Process(s, false, out);
    window.push_back(out.unfiltered);
    if (window.size() > 16) window.pop_front();
    for (std::size_t r = 0; r < kAxes; ++r) {
      double mean = 0;
      for (const auto& w : window) mean += w[r];
      mean /= static_cast<double>(window.size());
      EXPECT_LE(std::fabs(out.wrench[r] - mean), 0.5 + 1e-9) << "sample " << i << " axis " << r;
    }
  }
}

TEST(Core, SaturatedChannelHoldsLastValidWrenchAndSetsBit0) {
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0));
  core.SetLimits(CoreLimits{0, 0});
  CoreOutput out{};
  core.Process(Sample(100000, 5000), false, out);
  const WrenchLsb valid = out.wrench;
  hal::AdcSample sat = Sample(4000000);
  sat.counts[3] = (1 << 23) - 1;
  sat.flags[3] = hal::kChannelSaturated;
  core.Process(sat, false, out);
  EXPECT_TRUE(out.status & kStatusSaturated);
  EXPECT_FALSE(out.updated);
  EXPECT_EQ(out.wrench, valid);
  core.Process(Sample(100000, 5000), false, out);
  EXPECT_FALSE(out.status & kStatusSaturated);
  EXPECT_TRUE(out.updated);
}

TEST(Core, NoCalibrationGivesZeroWrenchAndBit4) {
  WrenchCore core;
  CoreOutput out{};
  core.Process(Sample(100000), true, out);
  EXPECT_TRUE(out.status & kStatusCalInvalid);
  EXPECT_TRUE(out.status & kStatusSimulated);
  EXPECT_EQ(out.wrench, WrenchLsb{});
}

TEST(Core, StuckCountsSetAdcFaultAndPinnedRailSetsBridgeFault) {
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0));
  core.SetLimits(CoreLimits{10, 4});
  CoreOutput out{};
  for (int i = 0; i < 9; ++i) core.Process(Sample(12345), false, out);
  EXPECT_FALSE(out.status & kStatusAdcFault);  // 8 repeats after the first: not yet
  core.Process(Sample(12345), false, out);
  EXPECT_FALSE(out.status & kStatusAdcFault);
  core.Process(Sample(12345), false, out);
  EXPECT_TRUE(out.status & kStatusAdcFault);
  core.Process(Sample(54321), false, out);
  EXPECT_FALSE(out.status & kStatusAdcFault);

  hal::AdcSample open = Sample(1000, 7);
  open.counts[2] = (1 << 23) - 1;  // open gauge drives the bridge to the rail
  open.flags[2] = hal::kChannelSaturated;
  for (int i = 0; i < 3; ++i) {
    open.counts[0] += 1;
    core.Process(open, false, out);
    EXPECT_FALSE(out.status & kStatusBridgeFault) << i;
  }
  open.counts[0] += 1;
  core.Process(open, false, out);
  EXPECT_TRUE(out.status & kStatusBridgeFault);
  EXPECT_TRUE(out.status & kStatusSaturated);
}

TEST(Core, InputsBeyondTheRailsAreClampedAndFlagged) {
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0));
  std::array<std::int32_t, kMaxChannels> x{};
  x[0] = (1 << 23) + 500;  // a broken driver handing out-of-range counts
  WrenchLsb y{};
  bool sat = false;
  core.Apply(x, y, &sat);
  EXPECT_TRUE(sat);
  std::array<std::int32_t, kMaxChannels> rail{};
  rail[0] = (1 << 23) - 1;
  WrenchLsb y_rail{};
  bool sat2 = false;
  core.Apply(rail, y_rail, &sat2);
  EXPECT_FALSE(sat2);
  EXPECT_EQ(y, y_rail);
}

TEST(Core, PoweredUpUnderLoadIsSaturationNotABridgeFault) {
  // The first sample already has bridges 0, 2 and 4 at the lower rail (a large Fz, as the
  // built-in sensor under 900 N): a load, not an open gauge.
  WrenchCore core;
  core.SetCalibration(DiagonalCal(100.0));
  core.SetLimits(CoreLimits{10, 4});
  hal::AdcSample s = Sample(1000, 6);
  for (const int c : {0, 2, 4}) {
    s.counts[c] = -(1 << 23);
    s.flags[c] = hal::kChannelSaturated;
  }
  CoreOutput out{};
  for (int i = 0; i < 20; ++i) {
    s.counts[1] += 1;
    core.Process(s, false, out);
    EXPECT_FALSE(out.status & kStatusBridgeFault) << i;
    EXPECT_TRUE(out.status & kStatusSaturated) << i;
    EXPECT_TRUE(out.saturated_by_load) << i;
  }
  // One channel alone at a rail from the first sample: an open gauge (bridge fault).
  WrenchCore lone;
  lone.SetCalibration(DiagonalCal(100.0));
  lone.SetLimits(CoreLimits{10, 4});
  hal::AdcSample one = Sample(1000, 6);
  one.counts[3] = (1 << 23) - 1;
  one.flags[3] = hal::kChannelSaturated;
  for (int i = 0; i < 4; ++i) {
    one.counts[0] += 1;
    lone.Process(one, false, out);
  }
  EXPECT_TRUE(out.status & kStatusBridgeFault);
  EXPECT_FALSE(out.saturated_by_load);
}

}  // namespace
}  // namespace ftstack::fw
