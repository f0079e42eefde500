// Time as it is (issue 12): the diagnosis's stateful filters on jittered clocks against an
// independent fine-step Runge-Kutta integration; segments restart them and bound hold-out blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
#include "diagnosis/loader/data.hpp"
#include "measurement/recording.hpp"

namespace ftstack::diag {
namespace {

/// ±30 % jittered clock at 150 Hz and a test input (steps, a ramp and a sine).
void Clock(std::vector<double>* t, std::vector<double>* x, int n) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  double tt = 0.0;
  for (int i = 0; i < n; ++i) {
    t->push_back(tt);
    x->push_back((i / 97) % 2 == 0 ? 1.0 : -0.5 + 0.01 * (i % 97) + 0.3 * std::sin(7.0 * tt));
    tt += (1.0 + u(rng)) / 150.0;
  }
}

/// Reference: RK4 with 200 substeps per sample on the input interpolated linearly in time.
std::vector<double> Rk4SecondOrder(const std::vector<double>& t, const std::vector<double>& x,
                                   double f, double zeta) {
  const double w = 2.0 * M_PI * f;
  double y = x[0];
  double v = 0.0;
  std::vector<double> out{y};
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double h = (t[i] - t[i - 1]) / 200.0;
    auto u = [&](double s) { return x[i - 1] + (x[i] - x[i - 1]) * s / (t[i] - t[i - 1]); };
    auto acc = [&](double s, double yy, double vv) {
      return w * w * (u(s) - yy) - 2.0 * zeta * w * vv;
    };
    for (int k = 0; k < 200; ++k) {
      const double s = k * h;
      const double k1y = v;
      const double k1v = acc(s, y, v);
      const double k2y = v + 0.5 * h * k1v;
      const double k2v = acc(s + 0.5 * h, y + 0.5 * h * k1y, v + 0.5 * h * k1v);
      const double k3y = v + 0.5 * h * k2v;
      const double k3v = acc(s + 0.5 * h, y + 0.5 * h * k2y, v + 0.5 * h * k2v);
      const double k4y = v + h * k3v;
      const double k4v = acc(s + h, y + h * k3y, v + h * k3v);
      y += h / 6.0 * (k1y + 2 * k2y + 2 * k3y + k4y);
      v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    out.push_back(y);
  }
  return out;
}

TEST(DiagTime, SecondOrderLowPassIsExactOnAJitteredClock) {
  std::vector<double> t;
  std::vector<double> x;
  Clock(&t, &x, 600);
  // Under-, near-critically and over-damped, low and near-Nyquist frequencies.
  for (const auto& [f, z] : std::vector<std::pair<double, double>>{
           {3.0, 0.02}, {40.0, 0.1}, {10.0, 1.0}, {10.0, 1.00000001}, {5.0, 1.8}, {60.0, 0.3}}) {
    std::vector<double> y(t.size());
    SecondOrderLowPass(t.data(), x.data(), t.size(), f, z, y.data());
    const std::vector<double> ref = Rk4SecondOrder(t, x, f, z);
    double worst = 0.0;
    for (std::size_t i = 0; i < t.size(); ++i) worst = std::max(worst, std::fabs(y[i] - ref[i]));
    EXPECT_LT(worst, 1e-7) << "f " << f << " zeta " << z;
  }
}

TEST(DiagTime, FirstOrderLowPassColumnsMatchesTheClosedFormPerColumn) {
  std::vector<double> t;
  std::vector<double> x;
  Clock(&t, &x, 400);
  std::vector<double> x2(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) x2[i] = -2.0 * x[i] + 1.0;
  std::vector<double> y1(x.size());
  std::vector<double> y2(x.size());
  const double* in[2] = {x.data(), x2.data()};
  double* out[2] = {y1.data(), y2.data()};
  FirstOrderLowPassColumns(t.data(), t.size(), 0.05, in, out, 2);
  // Independent: exact solution of τẏ + y = u for u linear over each step.
  double y = x[0];
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double dt = t[i] - t[i - 1];
    const double k = (x[i] - x[i - 1]) / dt;
    // y(t) = u(t) − τk + (y0 − u0 + τk)·e^{−dt/τ}
    y = x[i] - 0.05 * k + (y - x[i - 1] + 0.05 * k) * std::exp(-dt / 0.05);
    EXPECT_NEAR(y1[i], y, 1e-12);
    EXPECT_NEAR(y2[i], -2.0 * y + 1.0, 1e-12);
  }
}

TEST(DiagTime, SegmentsRestartFiltersAndBoundHoldOutBlocks) {
  // Three recordings joined: a `segment` column, then the same by time gaps alone.
  std::string text = "t,segment,b0\n";
  double t = 0.0;
  for (int s = 0; s < 3; ++s) {
    for (int i = 0; i < 250 + 37 * s; ++i) {
      text += std::to_string(t) + "," + std::to_string(7 - s) + "," + std::to_string(s) + "\n";
      t += 0.01;
    }
    t += 5.0;
  }
  const Recording with_col = ParseRecording(text, "seg.csv");
  const std::vector<int> seg = FindSegments(with_col);
  ASSERT_EQ(seg.size(), with_col.rows());
  EXPECT_EQ(seg.front(), 0);
  EXPECT_EQ(seg[250], 1);
  EXPECT_EQ(seg.back(), 2);
  Recording gaps = with_col;
  gaps.names[1] = "other";
  EXPECT_EQ(FindSegments(gaps), seg);
  // Filters: each segment starts at rest at its first input, as if recorded alone.
  const auto& tt = with_col.Column("t");
  const auto& x = with_col.Column("b0");
  std::vector<double> y(x.size());
  const double* in[1] = {x.data()};
  double* out[1] = {y.data()};
  std::vector<std::uint8_t> restart(x.size(), 0);
  for (std::size_t i = 1; i < x.size(); ++i) restart[i] = seg[i] != seg[i - 1] ? 1 : 0;
  FirstOrderLowPassColumns(tt.data(), tt.size(), 1.0, in, out, 1, restart.data());
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_DOUBLE_EQ(y[i], x[i]);  // constant per segment
  SecondOrderLowPassColumns(tt.data(), tt.size(), 2.0, 0.1, in, out, 1, restart.data());
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(y[i], x[i], 1e-12);
  // Hold-out blocks never straddle a boundary: train/hold is constant within each block and a new
  // block starts at every segment's first row.
  DiagData d;
  d.t_s = tt;
  d.segment = seg;
  const auto n = static_cast<Eigen::Index>(tt.size());
  d.sim_mvv = Eigen::MatrixXd::Zero(n, 1);
  d.real_mvv = Eigen::MatrixXd::Random(n, 1) * 1e-3;
  const Context cx = MakeContext(d, 0.2);
  EXPECT_EQ(cx.segments, 3);
  // Expected: 20-row blocks counted from each segment's first row, every third one held out.
  int block = -1;
  int start = 0;
  for (std::size_t i = 0; i < tt.size(); ++i) {
    if (i == 0 || seg[i] != seg[i - 1]) {
      ++block;
      start = static_cast<int>(i);
    } else if ((static_cast<int>(i) - start) % 20 == 0) {
      ++block;
    }
    EXPECT_EQ(cx.train[i], block % 3 == 1 ? 0 : 1) << i;
  }
  std::size_t held_across = 0;
  for (std::size_t i = 1; i < tt.size(); ++i) {
    if (seg[i] != seg[i - 1] && cx.train[i] == 0 && cx.train[i - 1] == 0) ++held_across;
  }
  EXPECT_EQ(held_across, 0u);
}

}  // namespace
}  // namespace ftstack::diag
