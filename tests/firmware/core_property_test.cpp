// Property test: the fixed-point core agrees with a long-double reference within 1 output LSB.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "firmware/core.hpp"
#include "firmware/fixed_calibration.hpp"

namespace ftstack::fw {
namespace {

hal::AdcInfo Adc24(std::uint8_t n) {
  hal::AdcInfo a;
  a.channel_count = n;
  a.max_counts = (1 << 23) - 1;
  a.min_counts = -(1 << 23);
  a.full_scale_nvv = 3906250;  // ±3.90625 mV/V
  a.rate_hz = 1000;
  return a;
}

// Reference in physical units, long double: w = M·(counts/cpm − offset) + bias (or with tare:
// M·(counts − tare)/cpm), converted to output LSB.
long double Reference(const FloatCalibration& cal, const hal::AdcInfo& adc, std::size_t r,
                      const std::array<std::int32_t, kMaxChannels>& counts,
                      const std::array<std::int32_t, kMaxChannels>* tare) {
  const long double cpm = static_cast<long double>(adc.max_counts) /
                          (static_cast<long double>(adc.full_scale_nvv) * 1e-6L);
  long double w = tare ? 0.0L : static_cast<long double>(cal.bias[r]);
  for (std::size_t c = 0; c < cal.channel_count; ++c) {
    const long double mvv = tare ? (static_cast<long double>(counts[c]) - (*tare)[c]) / cpm
                                 : static_cast<long double>(counts[c]) / cpm - cal.offset_mvv[c];
    w += static_cast<long double>(cal.matrix[r][c]) * mvv;
  }
  return w / static_cast<long double>(AxisLsb(r));
}

// Independent worst-case |output| over all inputs between the rails (either zero reference).
long double WorstCase(const FloatCalibration& cal, const hal::AdcInfo& adc, std::size_t r) {
  const long double cpm = static_cast<long double>(adc.max_counts) /
                          (static_cast<long double>(adc.full_scale_nvv) * 1e-6L);
  const long double span = static_cast<long double>(adc.max_counts) - adc.min_counts;
  long double sum = 0;
  long double bias = cal.bias[r];
  for (std::size_t c = 0; c < cal.channel_count; ++c) {
    sum += std::fabs(static_cast<long double>(cal.matrix[r][c])) / cpm * span;
    bias -= static_cast<long double>(cal.matrix[r][c]) * cal.offset_mvv[c];
  }
  return (sum + std::fabs(bias)) / static_cast<long double>(AxisLsb(r));
}

struct Case {
  FloatCalibration cal;
  hal::AdcInfo adc;
};

// Random calibration: per-row magnitude log-uniform over 12 decades (well and badly scaled
// rows), per-entry spread up to 6 decades inside a row, random signs, offsets and bias.
Case RandomCase(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> n_dist(1, 8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Case k;
  const auto n = static_cast<std::uint8_t>(n_dist(rng));
  k.adc = Adc24(n);
  k.cal.channel_count = n;
  const bool badly_scaled = u(rng) < 0.5;
  for (std::size_t r = 0; r < kAxes; ++r) {
    // Row magnitude in physical units per mV/V: 1e-4 … 1e8 (forces) — many overflow at the top.
    const double row_mag = std::pow(10.0, -4.0 + 12.0 * u(rng)) * (r < 3 ? 1.0 : 0.05);
    for (std::size_t c = 0; c < n; ++c) {
      const double spread = badly_scaled ? std::pow(10.0, -6.0 * u(rng)) : 0.2 + 0.8 * u(rng);
      k.cal.matrix[r][c] = (u(rng) < 0.5 ? -1 : 1) * row_mag * spread;
    }
    k.cal.bias[r] = (u(rng) - 0.5) * row_mag * 0.1;
  }
  for (std::size_t c = 0; c < n; ++c) k.cal.offset_mvv[c] = (u(rng) - 0.5) * 0.5;
  return k;
}

std::array<std::int32_t, kMaxChannels> RandomCounts(std::mt19937_64& rng, const hal::AdcInfo& a) {
  std::uniform_int_distribution<std::int32_t> any(a.min_counts, a.max_counts);
  std::uniform_int_distribution<int> pick(0, 5);
  std::array<std::int32_t, kMaxChannels> x{};
  for (std::size_t c = 0; c < a.channel_count; ++c) {
    switch (pick(rng)) {
      case 0:
        x[c] = a.max_counts;  // positive rail
        break;
      case 1:
        x[c] = a.min_counts;  // negative rail
        break;
      case 2:
        x[c] = 0;
        break;
      default:
        x[c] = any(rng);
    }
  }
  return x;
}

TEST(CoreProperty, WithinOneLsbOfLongDoubleReferenceOrRefusedForOverflow) {
  std::mt19937_64 rng(20261122);
  int accepted = 0;
  int refused = 0;
  long double max_err_lsb = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Case k = RandomCase(rng);
    FixedCalibration fixed{};
    LoadReport rep{};
    const LoadStatus s = LoadCalibration(k.cal, k.adc, &fixed, &rep);
    long double worst = 0;
    for (std::size_t r = 0; r < kAxes; ++r) worst = std::max(worst, WorstCase(k.cal, k.adc, r));
    constexpr long double kInt32Max = 2147483647.0L;
    if (s == LoadStatus::kOutputOverflow) {
      ++refused;
      // Refusal must be justified: some row can really leave int32 (1 LSB slack for rounding).
      EXPECT_GT(worst, kInt32Max - 2) << "trial " << trial;
      continue;
    }
    ASSERT_EQ(s, LoadStatus::kOk) << "trial " << trial;
    EXPECT_LE(worst, kInt32Max) << "trial " << trial << ": accepted a calibration that overflows";
    ++accepted;
    WrenchCore core;
    core.SetCalibration(fixed);
    for (int i = 0; i < 25; ++i) {
      const auto x = RandomCounts(rng, k.adc);
      WrenchLsb y{};
      bool sat = false;
      core.Apply(x, y, &sat);
      EXPECT_FALSE(sat);
      for (std::size_t r = 0; r < kAxes; ++r) {
        const long double ref = Reference(k.cal, k.adc, r, x, nullptr);
        const long double err = std::fabs(static_cast<long double>(y[r]) - ref);
        max_err_lsb = std::max(max_err_lsb, err);
        ASSERT_LE(err, 1.0L) << "trial " << trial << " row " << r << " ref "
                             << static_cast<double>(ref) << " got " << y[r];
        ASSERT_LE(err, static_cast<long double>(rep.worst_case_error_lsb[r]) + 1e-9L)
            << "error above the loader's own bound";
      }
    }
  }
  // Both branches must have been exercised by the generator.
  EXPECT_GT(accepted, 1000);
  EXPECT_GT(refused, 100);
  // The final rounding contributes up to 0.5 LSB; coefficient rounding stays well below the rest.
  EXPECT_GT(max_err_lsb, 0.4L);
  EXPECT_LT(max_err_lsb, 0.75L);
}

/// A core running `k`'s calibration (refused: false) with a tare taken on `samples` identical
/// samples at random counts (possibly at a rail); *held is that sample, *fixed the loaded form.
bool TaredCore(const Case& k, std::mt19937_64& rng, int samples, WrenchCore* core,
               FixedCalibration* fixed, hal::AdcSample* held) {
  LoadReport rep{};
  if (LoadCalibration(k.cal, k.adc, fixed, &rep) != LoadStatus::kOk) return false;
  core->SetCalibration(*fixed);
  core->SetLimits(CoreLimits{0, 0});
  *held = hal::AdcSample{};
  held->channel_count = k.cal.channel_count;
  held->counts = RandomCounts(rng, k.adc);
  if (!core->RequestTare(static_cast<std::uint16_t>(samples))) return false;
  CoreOutput out{};
  for (int i = 0; i < samples; ++i) core->Process(*held, false, out);  // flags clear: accepted
  return core->tare_active();
}

TEST(CoreProperty, TaredPathWithinOneLsbIncludingRailToRail) {
  std::mt19937_64 rng(7);
  int checked = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    const Case k = RandomCase(rng);
    FixedCalibration fixed{};
    WrenchCore core;
    hal::AdcSample held{};
    if (!TaredCore(k, rng, 4, &core, &fixed, &held)) continue;  // refused calibrations
    const auto tare = held.counts;
    for (int i = 0; i < 10; ++i) {
      const auto x = RandomCounts(rng, k.adc);
      WrenchLsb y{};
      bool sat = false;
      core.Apply(x, y, &sat);
      ASSERT_FALSE(sat);
      for (std::size_t r = 0; r < kAxes; ++r) {
        const long double ref = Reference(k.cal, k.adc, r, x, &tare);
        ASSERT_LE(std::fabs(static_cast<long double>(y[r]) - ref), 1.0L) << "trial " << trial;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 3000);
}

/// The load on the body (CoreOutput::structural, what overload and peaks judge) ignores the tare:
/// after a tare it still matches the untared double reference within 2 LSB (1 for the tared path,
/// 1 for the tare's own wrench rounded on its own).
TEST(CoreProperty, StructuralLoadIgnoresTheTareWithinTwoLsb) {
  std::mt19937_64 rng(13);
  int checked = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Case k = RandomCase(rng);
    FixedCalibration fixed{};
    WrenchCore core;
    hal::AdcSample s{};
    if (!TaredCore(k, rng, 2, &core, &fixed, &s)) continue;  // refused calibrations
    CoreOutput out{};
    for (int i = 0; i < 5; ++i) {
      s.counts = RandomCounts(rng, k.adc);
      core.Process(s, false, out);
      // A count that lands on a rail in one step from mid-range reads as a broken gauge, for
      // which there is no load to report; every other sample carries it.
      bool at_rail = false;
      for (std::size_t c = 0; c < s.channel_count; ++c) {
        at_rail = at_rail || s.counts[c] >= fixed.max_counts || s.counts[c] <= fixed.min_counts;
      }
      if (at_rail) continue;
      ASSERT_TRUE(out.structural_valid);
      for (std::size_t r = 0; r < kAxes; ++r) {
        const long double ref = Reference(k.cal, k.adc, r, s.counts, nullptr);
        if (std::fabs(ref) > 2.0e9L) continue;  // beyond int32: clipped by design
        ASSERT_LE(std::fabs(static_cast<long double>(out.structural[r]) - ref), 2.0L)
            << "trial " << trial << " axis " << r;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(CoreLoader, RefusesNonFiniteAndBadShapesAndKeepsPreviousCalibration) {
  const hal::AdcInfo adc = Adc24(6);
  FloatCalibration cal{};
  cal.channel_count = 6;
  for (std::size_t r = 0; r < kAxes; ++r) cal.matrix[r][r] = 100.0;
  FixedCalibration fixed{};
  ASSERT_EQ(LoadCalibration(cal, adc, &fixed, nullptr), LoadStatus::kOk);
  const FixedCalibration before = fixed;

  FloatCalibration bad = cal;
  bad.matrix[2][3] = NAN;
  EXPECT_EQ(LoadCalibration(bad, adc, &fixed, nullptr), LoadStatus::kNotFinite);
  bad = cal;
  bad.bias[5] = INFINITY;
  EXPECT_EQ(LoadCalibration(bad, adc, &fixed, nullptr), LoadStatus::kNotFinite);
  bad = cal;
  bad.channel_count = 0;
  EXPECT_EQ(LoadCalibration(bad, adc, &fixed, nullptr), LoadStatus::kBadChannelCount);
  bad = cal;
  bad.channel_count = 5;  // ADC has 6
  EXPECT_EQ(LoadCalibration(bad, adc, &fixed, nullptr), LoadStatus::kBadChannelCount);
  hal::AdcInfo no_scale = adc;
  no_scale.full_scale_nvv = 0;
  EXPECT_EQ(LoadCalibration(cal, no_scale, &fixed, nullptr), LoadStatus::kBadAdcScaling);
  bad = cal;
  bad.matrix[0][0] = 1e9;  // 1e9 N per mV/V · 3.9 mV/V · 2 ≫ int32 mN
  LoadReport rep{};
  EXPECT_EQ(LoadCalibration(bad, adc, &fixed, &rep), LoadStatus::kOutputOverflow);
  EXPECT_EQ(rep.failing_axis, 0);
  // Every refusal left the previous fixed-point form untouched.
  EXPECT_EQ(fixed.coef, before.coef);
  EXPECT_EQ(fixed.shift, before.shift);
  EXPECT_TRUE(fixed.valid);
}

TEST(CoreLoader, ReportsWorstCaseErrorInPhysicalUnits) {
  const hal::AdcInfo adc = Adc24(6);
  FloatCalibration cal{};
  cal.channel_count = 6;
  for (std::size_t r = 0; r < kAxes; ++r) {
    for (std::size_t c = 0; c < 6; ++c)
      cal.matrix[r][c] = (r < 3 ? 150.0 : 8.0) * (r == c ? 1 : 0.1);
  }
  FixedCalibration fixed{};
  LoadReport rep{};
  ASSERT_EQ(LoadCalibration(cal, adc, &fixed, &rep), LoadStatus::kOk);
  for (std::size_t r = 0; r < kAxes; ++r) {
    // The bound is the final half-LSB rounding plus a tiny coefficient-rounding term and the
    // narrow (32-bit coefficient) form's rounding, which the loader accepts up to 1/16 LSB.
    EXPECT_GE(rep.worst_case_error_lsb[r], 0.5);
    EXPECT_LT(rep.worst_case_error_lsb[r], 0.501 + 1.0 / 16.0);
    EXPECT_DOUBLE_EQ(rep.worst_case_error_si[r], rep.worst_case_error_lsb[r] * AxisLsb(r));
    EXPECT_GE(fixed.shift[r], 20);  // well-scaled rows get a deep binary point
  }
  EXPECT_TRUE(fixed.narrow);  // a real sensor's matrix runs in the narrow form
}

}  // namespace
}  // namespace ftstack::fw
