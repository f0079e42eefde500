// The lag memo: a search's lag of the load, found in the memo, is exactly the filter's value at
// those rows, and a different τ or row set is never served another's lag.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "diagnosis/engine/lag_cache.hpp"
#include "diagnosis/engine/separable_fit.hpp"
#include "diagnosis/filters/lowpass.hpp"

namespace ftstack::diag {
namespace {

/// A jittered clock and a stepping load on three channels, with the memo on.
struct LagFixture {
  DiagData data;
  Context cx;
  LagFixture() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(0.7e-3, 1.3e-3);
    const int n = 5000;
    double t = 0.0;
    for (int i = 0; i < n; ++i) {
      data.t_s.push_back(t);
      t += jitter(rng);
    }
    cx.data = &data;
    cx.n = n;
    cx.nc = 3;
    Eigen::MatrixXd load(n, 3);
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) load(i, c) = ((i / 700 + c) % 3) * (1.0 + c) + 0.01 * i / n;
    }
    cx.load = std::move(load);
    cx.lag_cache = std::make_shared<LagCache>(std::size_t{1} << 20);
  }
  /// The whole filter over every row of channel c, at row i (the reference).
  [[nodiscard]] std::vector<double> Whole(double tau, int c) const {
    std::vector<double> y(static_cast<std::size_t>(cx.n));
    const double* x = cx.load.col(c).data();
    double* out = y.data();
    FirstOrderLowPassColumns(data.t_s.data(), y.size(), tau, &x, &out, 1);
    return y;
  }
};

void ExpectLagAt(const LagFixture& f, double tau, const std::vector<int>& rows) {
  fx::Mat lag;
  fx::LowPassLoadRows(f.cx, tau, rows, &lag);
  ASSERT_EQ(lag.rows(), static_cast<Eigen::Index>(rows.size()));
  for (int c = 0; c < f.cx.nc; ++c) {
    const std::vector<double> whole = f.Whole(tau, c);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      ASSERT_EQ(lag(static_cast<Eigen::Index>(r), c), whole[static_cast<std::size_t>(rows[r])])
          << "tau " << tau << " channel " << c << " row " << rows[r];
    }
  }
}

TEST(DiagLagMemo, FoundLagIsTheFiltersValueAndKeysAreExact) {
  LagFixture f;
  std::vector<int> every7;
  for (int i = 0; i < f.cx.n; i += 7) every7.push_back(i);
  std::vector<int> every11;
  for (int i = 3; i < f.cx.n; i += 11) every11.push_back(i);
  ExpectLagAt(f, 0.05, every7);  // filtered
  EXPECT_EQ(f.cx.lag_cache->misses(), 1U);
  ExpectLagAt(f, 0.05, every7);  // found
  EXPECT_EQ(f.cx.lag_cache->hits(), 1U);
  ExpectLagAt(f, 0.05, every11);                      // same τ, other rows: filtered
  ExpectLagAt(f, std::nextafter(0.05, 1.0), every7);  // τ one ulp away: filtered
  EXPECT_EQ(f.cx.lag_cache->hits(), 1U);
  EXPECT_EQ(f.cx.lag_cache->misses(), 3U);
}

TEST(DiagLagMemo, EvictsTheLeastRecentlyUsedWithinItsBudget) {
  // Each lag of 1000 rows × 1 channel is 8 kB + 4 kB of rows: a 30 kB budget keeps two.
  LagCache memo(30000);
  const std::vector<int> rows(1000, 0);
  const auto lag = [](double v) {
    return std::make_shared<const Eigen::MatrixXd>(Eigen::MatrixXd::Constant(1000, 1, v));
  };
  memo.Insert(1.0, rows, lag(1.0));
  memo.Insert(2.0, rows, lag(2.0));
  ASSERT_NE(memo.Find(1.0, rows), nullptr);  // 1.0 now more recent than 2.0
  memo.Insert(3.0, rows, lag(3.0));          // evicts 2.0
  EXPECT_EQ(memo.Find(2.0, rows), nullptr);
  ASSERT_NE(memo.Find(1.0, rows), nullptr);
  ASSERT_NE(memo.Find(3.0, rows), nullptr);
  EXPECT_EQ((*memo.Find(3.0, rows))(0, 0), 3.0);
  LagCache tiny(100);  // a lag larger than the budget is not kept
  tiny.Insert(1.0, rows, lag(1.0));
  EXPECT_EQ(tiny.Find(1.0, rows), nullptr);
}

}  // namespace
}  // namespace ftstack::diag
