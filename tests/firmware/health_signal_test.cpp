// The health watch's integer signal blocks against closed forms computed here in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <set>
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

TEST(MeasureRinging, NoFrequencyWhileTheLoadStillMoves) {
  // A 25 Hz ringing (ζ 0.04, 3 000 LSB) whose load starts ramping at 25 LSB per sample in the
  // capture's last quarter: its halves' means differ by 1 600 LSB, more than the hysteresis plus
  // a quarter of the largest swing about that quarter's mean (≈ 20 + 4 600 / 4 LSB); with the
  // ramp 10× slower (160 LSB) the ringing is still measured.
  for (const double slope : {25.0, 2.5}) {
    const std::uint32_t rate = 1000;
    const double zeta = 0.04, wn = 2 * M_PI * 25.0, wd = wn * std::sqrt(1 - zeta * zeta);
    std::vector<std::int32_t> x(512);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double t = static_cast<double>(i) / rate;
      const double ramp = i < 384 ? 0.0 : slope * static_cast<double>(i - 384);
      x[i] = static_cast<std::int32_t>(
          std::lround(50000.0 + ramp + 3000.0 * std::exp(-zeta * wn * t) * std::cos(wd * t)));
    }
    const RingingResult r = MeasureRinging(x.data(), x.size(), rate, 20);
    if (slope > 10.0) {
      EXPECT_EQ(r.freq_mhz, 0) << "the load's ramp read as " << r.freq_mhz << " mHz";
    } else {
      EXPECT_NEAR(r.freq_mhz / 1000.0, wd / (2 * M_PI), wd / (2 * M_PI) * 0.02);
    }
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

/// ASTM E1049-85 § 5.4.4 rainflow (three-point rule with the starting point), on turning points
/// in double: the ranges of the full cycles (step 4) and of the half cycles (step 3: Y contains
/// the starting point; step 6: at the end, every range left).
struct AstmCycles {
  std::vector<double> full, half;
};
AstmCycles AstmCount(const std::vector<double>& peaks) {
  AstmCycles c;
  std::vector<double> s;
  std::size_t start = 0;  // index in s of the starting point S
  for (const double p : peaks) {
    s.push_back(p);
    while (s.size() >= 3) {
      const std::size_t n = s.size();
      const double x = std::fabs(s[n - 1] - s[n - 2]);
      const double y = std::fabs(s[n - 2] - s[n - 3]);
      if (x < y) break;
      if (n - 3 == start) {  // Y contains S: a half cycle; S moves on
        c.half.push_back(y);
        s.erase(s.begin() + static_cast<long>(start));
        continue;
      }
      c.full.push_back(y);
      s.erase(s.begin() + static_cast<long>(n - 3), s.begin() + static_cast<long>(n - 1));
    }
  }
  for (std::size_t i = start + 1; i < s.size(); ++i) c.half.push_back(std::fabs(s[i] - s[i - 1]));
  return c;
}
int AstmFullCycles(const std::vector<double>& peaks, double min_range) {
  int full = 0;
  for (const double r : AstmCount(peaks).full) full += r >= min_range ? 1 : 0;
  return full;
}
/// Full cycles per range bin, binned here: bin k holds ranges with edge[k − 1] ≤ range < edge[k]
/// (the first from 0, the last unbounded), the edges as fractions of `rated`.
std::vector<int> AstmBins(const std::vector<double>& ranges, const std::vector<double>& edge_frac,
                          double rated) {
  std::vector<int> bins(edge_frac.size() + 1, 0);
  for (const double r : ranges) {
    const auto above = std::upper_bound(edge_frac.begin(), edge_frac.end(), r / rated);
    ++bins[static_cast<std::size_t>(above - edge_frac.begin())];
  }
  return bins;
}

TEST(RainflowCounter, FullCyclesAndRangeBinsAgreeWithAstmE1049OnRandomHistories) {
  std::mt19937 rng(7);
  std::array<int, RainflowCounter::kBins> filled{};
  std::uniform_real_distribution<double> level(-100000.0, 100000.0);
  std::uniform_real_distribution<double> step(4500.0, 12000.0);
  std::bernoulli_distribution near(0.3);
  for (int history = 0; history < 20; ++history) {
    // Alternating turning points at least 2.25 gates apart (a third of them a small step from
    // the last, so that small ranges occur too), joined by ramps of 5 samples with noise below
    // the gate: the counter must find exactly these turning points.
    // No level twice: two neighbouring ranges are equal only where two turning points have the
    // same level, and at such a tie with the starting point the standard's three-point rule
    // drops the starting point (a half cycle) where the four-point rule keeps it.
    std::vector<double> peaks = {0.0};
    std::set<long> levels = {0};
    while (peaks.size() < 400) {
      const bool up = peaks.size() % 2 == 1;
      const double v =
          std::round(near(rng) ? peaks.back() + (up ? 1 : -1) * step(rng) : level(rng));
      if (((up && v > peaks.back() + 4500) || (!up && v < peaks.back() - 4500)) &&
          levels.insert(std::lround(v)).second) {
        peaks.push_back(v);
      }
    }
    // Bins as the watch sets them for a rated range of 100 000 LSB (5 … 100 %).
    RainflowCounter c;
    c.Configure(2000, 20000, {5000, 10000, 20000, 40000, 60000, 80000, 100000});
    std::uniform_int_distribution<int> noise(-400, 400);
    for (std::size_t i = 1; i < peaks.size(); ++i) {
      for (int k = 0; k < 5; ++k) {
        const double v = peaks[i - 1] + (peaks[i] - peaks[i - 1]) * k / 5.0;
        c.Add(static_cast<std::int32_t>(std::lround(v)) + (k == 0 ? 0 : noise(rng)));
      }
    }
    c.Add(static_cast<std::int32_t>(std::lround(peaks.back())));
    // Back from the last turning point by more than the gate (peaks alternate, the first one
    // up): it becomes a turning point too.
    c.Add(static_cast<std::int32_t>(
        std::lround(peaks.back() + (peaks.size() % 2 == 0 ? -3000 : 3000))));
    std::vector<double> rounded;
    for (const double p : peaks) rounded.push_back(static_cast<double>(std::lround(p)));
    EXPECT_EQ(static_cast<int>(c.cycles()), AstmFullCycles(rounded, 20000)) << history;
    EXPECT_GT(c.cycles(), 50u);
    const std::vector<int> want =
        AstmBins(AstmCount(rounded).full, {0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0}, 100000.0);
    for (std::size_t k = 0; k < RainflowCounter::kBins; ++k) {
      EXPECT_EQ(static_cast<int>(c.bins()[k]), want[k]) << history << " bin " << k;
    }
    // Every bin is exercised over the 20 histories (checked once, below).
    for (std::size_t k = 0; k < RainflowCounter::kBins; ++k) filled[k] += want[k];
  }
  for (std::size_t k = 0; k < RainflowCounter::kBins; ++k) EXPECT_GT(filled[k], 0) << "bin " << k;
}

TEST(RainflowCounter, AstmE1049WorkedExampleFullCyclesInBinsAndHalfCyclesInTheResidue) {
  // ASTM E1049-85, Fig. 6: -2 1 -3 5 -1 3 -4 4 -2 (units of 1000 LSB). The standard's rainflow
  // table: range 3: 0.5, 4: 1.5, 6: 0.5, 8: 1.0, 9: 0.5 cycles (one full cycle, range 4; six
  // half cycles). One bin per unit of range here: edges 2.5, 3.5, … 8.5 units.
  const std::vector<double> history = {-2, 1, -3, 5, -1, 3, -4, 4, -2};
  const std::map<int, double> table = {{3, 0.5}, {4, 1.5}, {6, 0.5}, {8, 1.0}, {9, 0.5}};
  // The independent implementation reproduces the published table.
  std::map<int, double> astm;
  const AstmCycles ref = AstmCount(history);
  for (const double r : ref.full) astm[static_cast<int>(r)] += 1.0;
  for (const double r : ref.half) astm[static_cast<int>(r)] += 0.5;
  EXPECT_EQ(astm, table);

  RainflowCounter c;
  c.Configure(500, 1, {2500, 3500, 4500, 5500, 6500, 7500, 8500});
  for (const double v : history) c.Add(static_cast<std::int32_t>(v * 1000));
  c.Add(-1000);  // the load turns back up by more than the gate: -2 is a turning point
  std::map<int, double> got;
  for (std::size_t k = 1; k < RainflowCounter::kBins; ++k) {  // bin k: range k + 2 units
    if (c.bins()[k] != 0) got[static_cast<int>(k) + 2] += c.bins()[k];
  }
  EXPECT_EQ(c.bins()[0], 0u);
  EXPECT_EQ(c.cycles(), 1u);
  // The residue's neighbouring points are the half cycles the standard counts at the end.
  ASSERT_EQ(c.residue_size(), 7u);
  for (std::size_t i = 1; i < c.residue_size(); ++i) {
    got[std::abs(c.residue(i) - c.residue(i - 1)) / 1000] += 0.5;
  }
  EXPECT_EQ(got, table);
}

TEST(RainflowCounter, NoiseBelowTheGateCountsNothing) {
  RainflowCounter c;
  c.Configure(2000, 1, {});
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> noise(-999, 999);
  for (int i = 0; i < 100000; ++i) c.Add(50000 + noise(rng));
  EXPECT_EQ(c.cycles(), 0u);
}

}  // namespace
}  // namespace ftstack::fw
