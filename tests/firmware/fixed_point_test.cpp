// The division-free rounding of the moving average against integer division over its whole range.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "firmware/core.hpp"
#include "firmware/fixed_point.hpp"

namespace ftstack::fw {
namespace {

// Largest |sum| the moving average divides: kMaxFilterLength wrenches of int32.
constexpr std::int64_t kMaxSum = std::int64_t{kMaxFilterLength} << 31;
// The domain RoundDivByReciprocal documents (|a| < 2^46, divisor ≤ 2^16).
constexpr std::int64_t kDomain = (std::int64_t{1} << 46) - 1;

// Every quotient boundary near `a`: the values around each multiple of d and each half-way point.
void CheckAround(std::int64_t a, std::uint32_t d, std::uint64_t m) {
  const std::int64_t base = a - a % d;
  for (std::int64_t k : {std::int64_t{0}, std::int64_t{d}, -std::int64_t{d}}) {
    for (std::int64_t off :
         {std::int64_t{-1}, std::int64_t{0}, std::int64_t{1}, std::int64_t{d / 2} - 1,
          std::int64_t{d / 2}, std::int64_t{d / 2} + 1, std::int64_t{d} - 1}) {
      for (std::int64_t s : {std::int64_t{1}, std::int64_t{-1}}) {
        const std::int64_t v = s * (base + k + off);
        if (v > kDomain || v < -kDomain) continue;
        ASSERT_EQ(RoundDivByReciprocal(v, d, m), RoundDiv(v, d)) << v << " / " << d;
      }
    }
  }
}

TEST(FixedPoint, ReciprocalDivisionEqualsIntegerDivisionForEveryFilterLength) {
  for (std::uint32_t d = 1; d <= kMaxFilterLength; ++d) {
    const std::uint64_t m = Reciprocal63(d);
    for (std::int64_t a = -(1 << 14); a <= (1 << 14); ++a) {  // every small sum
      ASSERT_EQ(RoundDivByReciprocal(a, d, m), RoundDiv(a, d)) << a << " / " << d;
    }
    // The top of the moving average's range and of the documented domain, boundaries included.
    for (std::int64_t top : {kMaxSum, kMaxSum - 1, kDomain, kDomain / 3, std::int64_t{1} << 32}) {
      CheckAround(top, d, m);
    }
  }
}

TEST(FixedPoint, ReciprocalDivisionOnRandomSumsAndWiderDivisors) {
  std::mt19937_64 rng(15);
  std::uniform_int_distribution<std::int64_t> sum(-kDomain, kDomain);
  std::uniform_int_distribution<std::uint32_t> div(1, 1U << 16);
  for (int i = 0; i < 2000000; ++i) {
    const std::uint32_t d =
        i % 2 == 0 ? 1 + static_cast<std::uint32_t>(i / 2) % kMaxFilterLength : div(rng);
    const std::int64_t a = sum(rng);
    ASSERT_EQ(RoundDivByReciprocal(a, d, Reciprocal63(d)), RoundDiv(a, d)) << a << " / " << d;
  }
  // A divisor at the top of the domain, around the largest quotient.
  CheckAround(kDomain - 70000, 1U << 16, Reciprocal63(1U << 16));
}

// The moving average of the core (which divides by multiplying) against a running integer mean.
TEST(FixedPoint, MovingAverageOfLargeWrenchesMatchesIntegerDivisionWhileFillingAndFull) {
  FloatCalibration cal{};
  cal.channel_count = 6;
  for (std::size_t r = 0; r < kAxes; ++r)
    cal.matrix[r][r] = r < 3 ? 2.0e5 : 2.0e3;  // outputs near ±2^31
  hal::AdcInfo adc;
  adc.channel_count = 6;
  adc.max_counts = (1 << 23) - 1;
  adc.min_counts = -(1 << 23);
  adc.full_scale_nvv = 3906250;
  FixedCalibration fixed{};
  ASSERT_EQ(LoadCalibration(cal, adc, &fixed, nullptr), LoadStatus::kOk);
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int32_t> counts(adc.min_counts + 1, adc.max_counts - 1);
  for (std::uint16_t len :
       {std::uint16_t{3}, std::uint16_t{7}, std::uint16_t{255}, std::uint16_t{256}}) {
    WrenchCore core;
    core.SetCalibration(fixed);
    core.SetLimits(CoreLimits{0, 0});
    ASSERT_TRUE(core.SetFilterLength(len));
    std::vector<WrenchLsb> history;
    for (int i = 0; i < 700; ++i) {
      hal::AdcSample s{};
      s.channel_count = 6;
      for (std::size_t c = 0; c < 6; ++c) s.counts[c] = counts(rng);
      CoreOutput out{};
      core.Process(s, false, out);
      ASSERT_TRUE(out.updated);
      history.push_back(out.unfiltered);
      const std::size_t used = history.size() < len ? history.size() : len;
      for (std::size_t r = 0; r < kAxes; ++r) {
        std::int64_t sum = 0;
        for (std::size_t k = history.size() - used; k < history.size(); ++k) sum += history[k][r];
        const std::int64_t q =
            sum >= 0
                ? (sum + static_cast<std::int64_t>(used / 2)) / static_cast<std::int64_t>(used)
                : -((-sum + static_cast<std::int64_t>(used / 2)) / static_cast<std::int64_t>(used));
        ASSERT_EQ(out.wrench[r], q) << "length " << len << " sample " << i << " axis " << r;
      }
    }
  }
}

}  // namespace
}  // namespace ftstack::fw
