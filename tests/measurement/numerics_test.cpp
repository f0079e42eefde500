// measurement/numerics: each routine against a closed form.
#include "measurement/numerics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace ftstack::numerics {
namespace {

TEST(Numerics, FirstOrderLagStepAndRampMatchTheExponential) {
  const double tau = 0.7;
  const double h = 0.013;
  const FohSystem sys = FirstOrderLagFoh(tau, h);
  EXPECT_NEAR(sys.phi(0, 0), std::exp(-h / tau), 1e-15);
  std::vector<double> step(400, 1.0);
  const auto y = FohResponse(sys, Eigen::RowVectorXd::Ones(1), Eigen::VectorXd::Zero(1), step);
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double t = static_cast<double>(k) * h;
    ASSERT_NEAR(y[k], 1.0 - std::exp(-t / tau), 1e-12) << k;
  }
  // A ramp u = t is linear between samples, so the first-order hold is exact:
  // x(t) = t − τ·(1 − e^{−t/τ}) from rest.
  std::vector<double> ramp(400);
  for (std::size_t k = 0; k < ramp.size(); ++k) ramp[k] = static_cast<double>(k) * h;
  const auto r = FohResponse(sys, Eigen::RowVectorXd::Ones(1), Eigen::VectorXd::Zero(1), ramp);
  for (std::size_t k = 0; k < r.size(); ++k) {
    const double t = ramp[k];
    ASSERT_NEAR(r[k], t - tau * (1.0 - std::exp(-t / tau)), 1e-12) << k;
  }
}

TEST(Numerics, SecondOrderStepMatchesTheUnderdampedResponse) {
  const double f = 3.0;
  const double zeta = 0.1;
  const double h = 0.004;
  const FohSystem sys = SecondOrderFoh(f, zeta, h);
  std::vector<double> step(600, 1.0);
  Eigen::RowVectorXd c(2);
  c << 1.0, 0.0;
  const auto y = FohResponse(sys, c, Eigen::Vector2d::Zero(), step);
  const double wn = 2.0 * std::numbers::pi * f;
  const double wd = wn * std::sqrt(1.0 - zeta * zeta);
  double peak = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double t = static_cast<double>(k) * h;
    const double want =
        1.0 - std::exp(-zeta * wn * t) *
                  (std::cos(wd * t) + zeta / std::sqrt(1.0 - zeta * zeta) * std::sin(wd * t));
    ASSERT_NEAR(y[k], want, 1e-10) << k;
    peak = std::max(peak, y[k]);
  }
  // Overshoot e^{−ζπ/√(1−ζ²)} (sampled near its time π/ω_d).
  EXPECT_NEAR(peak - 1.0, std::exp(-zeta * std::numbers::pi / std::sqrt(1.0 - zeta * zeta)), 2e-4);
}

TEST(Numerics, PlayOperatorFollowsOnlyPastItsHalfWidth) {
  // Triangle 0 → 2 → 0 in steps of 0.01, width 1 (half width 0.5).
  std::vector<double> x;
  for (int i = 0; i <= 200; ++i) x.push_back(0.01 * i);
  for (int i = 199; i >= 0; --i) x.push_back(0.01 * i);
  std::vector<double> z(x.size());
  PlayOperator(x.data(), x.size(), 1.0, z.data());
  for (std::size_t i = 0; i < x.size(); ++i) {
    double want = 0.0;
    if (i <= 200) {
      want = x[i] <= 0.5 ? -x[i] / 0.5 : -1.0;  // p stays at 0, then trails x by 0.5
    } else {
      want = x[i] >= 1.0 ? (1.5 - x[i]) / 0.5 : 1.0;  // p stays at 1.5, then leads x by 0.5
    }
    ASSERT_NEAR(z[i], want, 1e-12) << i << " x=" << x[i];
  }
  EXPECT_DOUBLE_EQ(PlayStep(0.0, 2.0, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(PlayStep(0.0, -2.0, 0.5), -1.5);
  EXPECT_DOUBLE_EQ(PlayStep(0.3, 0.0, 0.5), 0.3);
}

TEST(Numerics, WelchFindsASineAndTheWhiteNoiseLevel) {
  const double rate = 200.0;
  const std::size_t n = 40000;
  const std::size_t seg = WelchSegment(n);
  EXPECT_EQ(seg, 1024u);
  const double f = 50.0 * rate / 256.0;  // exactly on bin 256 of a 1024-point segment
  const double a = 0.3;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = a * std::sin(2.0 * std::numbers::pi * f * static_cast<double>(i) / rate + 0.4);
  }
  const Spectrum s = Welch(x.data(), n, rate, seg);
  ASSERT_EQ(s.power.size(), seg / 2 + 1);
  std::size_t peak = 0;
  for (std::size_t k = 0; k < s.power.size(); ++k) {
    if (s.power[k] > s.power[peak]) peak = k;
  }
  EXPECT_DOUBLE_EQ(s.freq_hz[peak], f);
  // Parseval: the bins around the line hold the sine's variance a²/2 as (2/segment)·Σ power.
  const double var =
      2.0 / static_cast<double>(seg) * (s.power[peak - 1] + s.power[peak] + s.power[peak + 1]);
  EXPECT_NEAR(var, a * a / 2.0, 1e-3 * a * a / 2.0);
  // White noise of variance σ² gives σ² per bin (mean over the band, 2 %: 39 segments × 400 bins).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 0.5);
  for (auto& v : x) v = normal(rng);
  const Spectrum w = Welch(x.data(), n, rate, seg);
  double mean = 0.0;
  for (std::size_t k = 50; k < 450; ++k) mean += w.power[k] / 400.0;
  EXPECT_NEAR(mean, 0.25, 0.02 * 0.25);
}

// The median of the periodograms: a weak line under a few large steps. The steps' leakage lifts
// the mean spectrum around the line; the median is that of the step-free segments, where the line
// stands 10^3 over white noise (closed form: a line of variance a²/2 in about one bin against σ²).
TEST(Numerics, WelchMedianKeepsALineThatStepsHideInTheMean) {
  const double rate = 10.0;
  const std::size_t n = 40000;
  const std::size_t seg = WelchSegment(n);
  const double f = 100.0 * rate / static_cast<double>(seg);  // on bin 100
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 0.01);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    x[i] = 0.05 * std::sin(2.0 * std::numbers::pi * f * t) + normal(rng) +
           (i % 10000 < 5000 ? 0.0 : 1000.0);  // 7 steps of 1000
  }
  const Spectrum mean = Welch(x.data(), n, rate, seg);
  const Spectrum median = WelchMedian(x.data(), n, rate, seg);
  ASSERT_EQ(median.power.size(), mean.power.size());
  const auto ratio = [](const Spectrum& s) { return s.power[100] / s.power[140]; };
  EXPECT_GT(ratio(median), 1000.0);
  EXPECT_LT(ratio(mean), 0.1 * ratio(median));
}

TEST(Numerics, GoldenSectionFindsTheVertexOfAParabola) {
  std::vector<double> grid;
  for (int i = 0; i <= 10; ++i) grid.push_back(0.5 * i);
  int calls = 0;
  const auto f = [&](double v) {
    ++calls;
    return 2.0 * (v - 1.234) * (v - 1.234) + 3.0;
  };
  double fmin = 0.0;
  const double x = MinimizeOnGrid(f, grid, 40, &fmin);
  EXPECT_NEAR(x, 1.234, 1e-7);
  EXPECT_NEAR(fmin, 3.0, 1e-13);
  EXPECT_EQ(calls, 11 + 2 + 40);
  // Without refinement: the best grid point.
  EXPECT_DOUBLE_EQ(MinimizeOnGrid(f, grid, 0, nullptr), 1.0);
}

}  // namespace
}  // namespace ftstack::numerics
