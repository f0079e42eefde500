// The health watch's integer signal blocks against closed forms computed here in double.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "firmware/health_signal.hpp"
#include "firmware/rainflow.hpp"

namespace ftstack::fw {
namespace {

/// Feeds `x` (whole block) to a tone detector on its first difference; amplitude in LSB.
double ToneAmplitude(const std::vector<double>& x, std::uint32_t freq, std::uint32_t rate) {
  ToneDetector t;
  const std::uint32_t block = static_cast<std::uint32_t>(x.size()) - 1;
  EXPECT_TRUE(t.Configure(freq, rate, block));
  for (std::size_t i = 1; i < x.size(); ++i) {
    t.Add(static_cast<std::int32_t>(std::lround(x[i]) - std::lround(x[i - 1])));
  }
  std::int64_t a = 0, p = 0;
  t.Finish(&a, &p);
  return a / 256.0;
}

struct ToneCase {
  std::uint32_t rate;
  std::uint32_t freq;
};
class ToneTest : public testing::TestWithParam<ToneCase> {};

TEST_P(ToneTest, AmplitudeOfATonePlusDcAndRamp) {
  const auto [rate, freq] = GetParam();
  const std::uint32_t block = rate / 10;
  for (const double amp : {40.0, 1000.0, 20000.0}) {
    std::vector<double> x(block + 1);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double t = static_cast<double>(i) / rate;
      // A DC offset and a ramp (a moving load) must not leak into the tone.
      x[i] = 123456.0 + 30000.0 * t + amp * std::sin(2 * M_PI * freq * t + 0.7);
    }
    EXPECT_NEAR(ToneAmplitude(x, freq, rate), amp, amp * 0.01 + 1.0) << rate << " " << freq;
    // The other mains frequency sits on another exact bin: it reads (almost) nothing.
    const std::uint32_t other = freq == 50 ? 60 : 50;
    EXPECT_LT(ToneAmplitude(x, other, rate), amp * 0.02 + 1.0);
  }
}
INSTANTIATE_TEST_SUITE_P(Rates, ToneTest,
                         testing::Values(ToneCase{1000, 50}, ToneCase{1000, 60}, ToneCase{8000, 50},
                                         ToneCase{8000, 60}, ToneCase{500, 50}));

TEST(ToneDetector, RefusesToneAtOrAboveNyquist) {
  ToneDetector t;
  EXPECT_FALSE(t.Configure(60, 100, 10));
  EXPECT_FALSE(t.Configure(50, 1000, 4));
}

TEST(MeasureRinging, DampedSineAfterAStep) {
  for (const double f : {25.0, 27.5, 80.0, 140.0}) {
    const std::uint32_t rate = 1000;
    std::vector<std::int32_t> x(512);
    const double zeta = 0.04, wn = 2 * M_PI * f, wd = wn * std::sqrt(1 - zeta * zeta);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double t = static_cast<double>(i) / rate;
      x[i] = static_cast<std::int32_t>(
          std::lround(50000.0 + 3000.0 * std::exp(-zeta * wn * t) * std::cos(wd * t)));
    }
    const RingingResult r = MeasureRinging(x.data(), x.size(), rate, 20);
    // The ringing is at the damped frequency; the count is exact to ±1 sample over the span.
    EXPECT_NEAR(r.freq_mhz / 1000.0, wd / (2 * M_PI), wd / (2 * M_PI) * 0.01) << f;
    EXPECT_GE(r.crossings, 4);
    EXPECT_NEAR(r.amplitude, 3000.0, 600.0);
  }
}

TEST(RingingScan, InSlicesMeasuresTheClosedFormAndTheWholeScansResult) {
  const std::uint32_t rate = 1000;
  const double zeta = 0.04, wn = 2 * M_PI * 25.0, wd = wn * std::sqrt(1 - zeta * zeta);
  std::vector<std::int32_t> x(512);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i) / rate;
    x[i] = static_cast<std::int32_t>(
        std::lround(-20000.0 + 3000.0 * std::exp(-zeta * wn * t) * std::cos(wd * t)));
  }
  const RingingResult whole = MeasureRinging(x.data(), x.size(), rate, 20);
  for (const std::size_t budget : {1u, 7u, 100u, 128u, 384u, 1000u}) {
    RingingScan scan;
    scan.Start(x.data(), x.size(), rate, 20);
    std::size_t calls = 1;
    while (!scan.Advance(budget)) ++calls;
    // The level's quarter (128 samples) and the crossings' 384, `budget` at a time, at most.
    EXPECT_LE(calls, (128 + budget - 1) / budget + (384 + budget - 1) / budget + 1) << budget;
    EXPECT_NEAR(scan.result().freq_mhz / 1000.0, wd / (2 * M_PI), wd / (2 * M_PI) * 0.01);
    EXPECT_EQ(scan.result().freq_mhz, whole.freq_mhz) << budget;
    EXPECT_EQ(scan.result().crossings, whole.crossings) << budget;
    EXPECT_EQ(scan.result().amplitude, whole.amplitude) << budget;
  }
  RingingScan idle;  // nothing started: final at once, no ringing
  EXPECT_TRUE(idle.Advance(1));
  EXPECT_EQ(idle.result().freq_mhz, 0);
}

TEST(MeasureRinging, NoRingingNoFrequency) {
  std::vector<std::int32_t> x(512, 1000);
  for (std::size_t i = 0; i < 40; ++i) x[i] = static_cast<std::int32_t>(i * 25);  // a ramp
  EXPECT_EQ(MeasureRinging(x.data(), x.size(), 1000, 5).freq_mhz, 0);
}

TEST(CreepRemaining, ExponentialApproachFromSegmentMeans) {
  // c(t) = C(1 − e^(−t/τ)): three segments of length L starting at t0; the remaining creep
  // averaged over segment 1 is the closed form C·τ/L·e^(−t0/τ)(1 − e^(−L/τ)).
  for (const double tau : {2.0, 10.0, 30.0}) {
    const double c = 400000.0, t0 = 0.8, len = 2.0;
    auto mean = [&](double a) {
      return c - c * tau / len * (std::exp(-a / tau) - std::exp(-(a + len) / tau));
    };
    const double want = c * tau / len * std::exp(-t0 / tau) * (1 - std::exp(-len / tau));
    const auto m = [&](int k) {
      return static_cast<std::int64_t>(std::lround(mean(t0 + k * len)));
    };
    const double got = static_cast<double>(CreepRemaining(m(0), m(1), m(2)));
    EXPECT_NEAR(got, want, want * 0.02 + 2.0) << tau;
  }
  // Not an exponential approach (growing increments): what was seen.
  EXPECT_EQ(CreepRemaining(0, 10, 30), 30);
}

/// ASTM E1049-85 rainflow (three-point rule with the starting point), on turning points in double:
/// the full cycles (step 4) with a range of at least `min_range`.
int AstmFullCycles(const std::vector<double>& peaks, double min_range) {
  std::vector<double> s;
  std::size_t start = 0;  // index in s of the starting point S
  int full = 0;
  for (const double p : peaks) {
    s.push_back(p);
    while (s.size() >= 3) {
      const std::size_t n = s.size();
      const double x = std::fabs(s[n - 1] - s[n - 2]);
      const double y = std::fabs(s[n - 2] - s[n - 3]);
      if (x < y) break;
      if (n - 3 == start) {  // Y contains S: a half cycle; S moves on
        s.erase(s.begin() + static_cast<long>(start));
        continue;
      }
      if (y >= min_range) ++full;
      s.erase(s.begin() + static_cast<long>(n - 3), s.begin() + static_cast<long>(n - 1));
    }
  }
  return full;
}

TEST(RainflowCounter, FullCyclesAgreeWithAstmE1049OnRandomHistories) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> level(-100000.0, 100000.0);
  for (int history = 0; history < 20; ++history) {
    // Alternating turning points at least 3 gates apart, joined by ramps of 5 samples with
    // noise below the gate: the counter must find exactly these turning points.
    std::vector<double> peaks = {0.0};
    while (peaks.size() < 400) {
      const double v = level(rng);
      const bool up = peaks.size() % 2 == 1;
      if ((up && v > peaks.back() + 6000) || (!up && v < peaks.back() - 6000)) peaks.push_back(v);
    }
    RainflowCounter c;
    c.Configure(2000, 20000);
    std::uniform_int_distribution<int> noise(-400, 400);
    for (std::size_t i = 1; i < peaks.size(); ++i) {
      for (int k = 0; k < 5; ++k) {
        const double v = peaks[i - 1] + (peaks[i] - peaks[i - 1]) * k / 5.0;
        c.Add(static_cast<std::int32_t>(std::lround(v)) + (k == 0 ? 0 : noise(rng)));
      }
    }
    c.Add(static_cast<std::int32_t>(std::lround(peaks.back())));
    c.Add(
        static_cast<std::int32_t>(std::lround(peaks.back() - (peaks.back() > 0 ? 1 : -1) * 3000)));
    std::vector<double> rounded;
    for (const double p : peaks) rounded.push_back(static_cast<double>(std::lround(p)));
    EXPECT_EQ(static_cast<int>(c.cycles()), AstmFullCycles(rounded, 20000)) << history;
    EXPECT_GT(c.cycles(), 50u);
  }
}

TEST(RainflowCounter, NoiseBelowTheGateCountsNothing) {
  RainflowCounter c;
  c.Configure(2000, 1);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> noise(-999, 999);
  for (int i = 0; i < 100000; ++i) c.Add(50000 + noise(rng));
  EXPECT_EQ(c.cycles(), 0u);
}

}  // namespace
}  // namespace ftstack::fw
