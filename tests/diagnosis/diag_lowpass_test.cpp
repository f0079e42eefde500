// The low passes on jittered clocks, gaps and restarts against an independent reference: the exact
// step of every row in long double (closed form for the first order, the matrix exponential of the
// augmented 4 × 4 system for the second), and the vector math kernels against libm.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
#include "diagnosis/filters/lowpass_kernels.hpp"

namespace ftstack::diag {
namespace {

using Ld = long double;
using Mat4 = std::array<std::array<Ld, 4>, 4>;

Mat4 Mul(const Mat4& a, const Mat4& b) {
  Mat4 c{};
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 4; ++k) {
      for (int j = 0; j < 4; ++j) c[i][j] += a[i][k] * b[k][j];
    }
  }
  return c;
}

/// e^M by scaling and squaring of its Taylor series (to degree 30 after scaling to ‖M‖₁ ≤ 1/2).
Mat4 Expm(Mat4 m) {
  Ld norm = 0;
  for (int j = 0; j < 4; ++j) {
    Ld col = 0;
    for (int i = 0; i < 4; ++i) col += std::fabs(m[i][j]);
    norm = std::max(norm, col);
  }
  int squarings = 0;
  while (norm > 0.5L) {
    norm /= 2;
    ++squarings;
  }
  for (auto& row : m) {
    for (Ld& v : row) v = std::ldexp(v, -squarings);
  }
  Mat4 sum{};
  Mat4 term{};
  for (int i = 0; i < 4; ++i) sum[i][i] = term[i][i] = 1;
  for (int k = 1; k <= 30; ++k) {
    term = Mul(term, m);
    for (auto& row : term) {
      for (Ld& v : row) v /= k;
    }
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) sum[i][j] += term[i][j];
    }
  }
  for (int s = 0; s < squarings; ++s) sum = Mul(sum, sum);
  return sum;
}

/// Second order, independently: state z = [y, ẏ/ω, u, u̇/ω] with the input linear over each step,
/// ż = M·z, z(t + dt) = e^{M dt}·z(t); at rest at the input where a recording starts.
std::vector<double> ReferenceSecondOrder(const std::vector<double>& t, const std::vector<double>& x,
                                         const std::vector<std::uint8_t>& restart, double f,
                                         double zeta) {
  const Ld w = 2 * static_cast<Ld>(M_PI) * f;
  Ld y = x[0];
  Ld v = 0;  // ẏ/ω
  std::vector<double> out{x[0]};
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (restart[i] != 0) {
      y = x[i];
      v = 0;
      out.push_back(x[i]);
      continue;
    }
    const Ld dt = static_cast<Ld>(t[i]) - t[i - 1];
    Mat4 m{};
    m[0][1] = w * dt;
    m[1][0] = -w * dt;
    m[1][1] = -2 * zeta * w * dt;
    m[1][2] = w * dt;
    m[2][3] = w * dt;
    const Mat4 e = Expm(m);
    const std::array<Ld, 4> z{y, v, static_cast<Ld>(x[i - 1]),
                              (x[i] - static_cast<Ld>(x[i - 1])) / (w * dt)};
    Ld zn[2] = {0, 0};
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 4; ++c) zn[r] += e[r][c] * z[c];
    }
    y = zn[0];
    v = zn[1];
    out.push_back(static_cast<double>(y));
  }
  return out;
}

/// First order, independently: τẏ + y = u for u linear over each step, closed form per step.
std::vector<double> ReferenceFirstOrder(const std::vector<double>& t, const std::vector<double>& x,
                                        const std::vector<std::uint8_t>& restart, double tau) {
  Ld y = x[0];
  std::vector<double> out{x[0]};
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (restart[i] != 0) {
      y = x[i];
    } else {
      const Ld dt = static_cast<Ld>(t[i]) - t[i - 1];
      const Ld tk = tau * (x[i] - static_cast<Ld>(x[i - 1])) / dt;  // τ·slope
      y = x[i] - tk + (y - x[i - 1] + tk) * std::exp(-dt / tau);
    }
    out.push_back(static_cast<double>(y));
  }
  return out;
}

struct Record {
  std::vector<double> t;
  std::vector<std::uint8_t> restart;
  std::vector<std::vector<double>> x;  // three columns
};

/// Three test inputs (steps, a ramp and a sine, pseudo-random values) on the clock of `rec`.
void AddInputs(Record* rec) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  rec->x.assign(3, {});
  for (std::size_t i = 0; i < rec->t.size(); ++i) {
    const double tt = rec->t[i];
    rec->x[0].push_back((i / 97) % 2 == 0 ? 1.0 : -0.5 + 0.01 * static_cast<double>(i % 97));
    rec->x[1].push_back(0.3 * std::sin(7.0 * tt) + 2.0);
    rec->x[2].push_back(u(rng));
  }
}

/// 1500 rows at a mean 150 Hz, every step jittered by up to ±30 %, timestamps to 12 decimals.
Record JitteredRecord() {
  Record rec;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  double tt = 0.0;
  for (int i = 0; i < 1500; ++i) {
    rec.t.push_back(std::round(tt * 1e12) / 1e12);
    tt += (1.0 + u(rng)) / 150.0;
  }
  rec.restart.assign(rec.t.size(), 0);
  AddInputs(&rec);
  return rec;
}

/// Jittered rows, a stretch on an exactly uniform clock, gaps of 3 s and 500 s filtered through, a
/// 40 s gap where a new recording starts, and restarts at the second row and at a chunk boundary.
Record GappyRecord() {
  Record rec = JitteredRecord();
  std::vector<double> t;
  double offset = 0.0;
  for (std::size_t i = 0; i < rec.t.size(); ++i) {
    if (i == 300) offset += 3.0;
    if (i == 700) offset += 500.0;
    if (i == 1100) offset += 40.0;
    if (i >= 400 && i < 650) {  // uniform: steps of exactly 2^-7 s
      t.push_back(t.back() + 0.0078125);
      offset = t.back() - rec.t[i];
      continue;
    }
    t.push_back(rec.t[i] + offset);
  }
  rec.t = t;
  for (std::size_t i : {std::size_t{1}, std::size_t{257}, std::size_t{1100}}) rec.restart[i] = 1;
  AddInputs(&rec);
  return rec;
}

double Scale(const Record& rec) {
  double s = 0.0;
  for (const auto& col : rec.x) {
    for (double v : col) s = std::max(s, std::fabs(v));
  }
  return s;
}

/// Filters the three columns of `rec` at once and returns the largest deviation from `ref`, a
/// reference per column, relative to the input scale.
/// The deviations seen are below 2e-13: what is left of rounding in the recursion (its particular
/// solution u − lag·slope cancels for slow filters); a series truncated a few terms early shows.
template <typename Filter, typename Reference>
double WorstDeviation(const Record& rec, Filter filter, Reference ref) {
  std::vector<std::vector<double>> y(3, std::vector<double>(rec.t.size()));
  const double* in[3] = {rec.x[0].data(), rec.x[1].data(), rec.x[2].data()};
  double* out[3] = {y[0].data(), y[1].data(), y[2].data()};
  filter(in, out);
  double worst = 0.0;
  for (std::size_t c = 0; c < 3; ++c) {
    const std::vector<double> r = ref(rec.x[c]);
    for (std::size_t i = 0; i < rec.t.size(); ++i) {
      worst = std::max(worst, std::fabs(y[c][i] - r[i]));
      if (rec.restart[i] != 0) {
        EXPECT_EQ(y[c][i], rec.x[c][i]) << "restart row " << i;
      }
    }
  }
  return worst / Scale(rec);
}

TEST(DiagLowPass, SecondOrderMatchesTheMatrixExponentialOnJitterGapsAndRestarts) {
  for (const Record& rec : {JitteredRecord(), GappyRecord()}) {
    for (double zeta : {0.01, 0.3, 0.999, 1.0, 1.000000001, 1.5}) {
      for (double f : {0.5, 5.0, 30.0, 67.5}) {  // 67.5 Hz = 0.45 × the mean rate
        const double worst = WorstDeviation(
            rec,
            [&](const double* const* in, double* const* out) {
              SecondOrderLowPassColumns(rec.t.data(), rec.t.size(), f, zeta, in, out, 3,
                                        rec.restart.data());
            },
            [&](const std::vector<double>& x) {
              return ReferenceSecondOrder(rec.t, x, rec.restart, f, zeta);
            });
        EXPECT_LT(worst, 1e-12) << "f " << f << " zeta " << zeta;
      }
    }
  }
}

TEST(DiagLowPass, FirstOrderMatchesTheClosedFormOnJitterGapsAndRestarts) {
  for (const Record& rec : {JitteredRecord(), GappyRecord()}) {
    // dt/τ from about 3 down to 7e-6; for τ ≫ dt the former (1 − e^{−r})/r lost digits (2e-10
    // at τ = 1000 s), the series keeps them.
    for (double tau : {0.003, 0.02, 0.3, 50.0, 1000.0}) {
      const double worst = WorstDeviation(
          rec,
          [&](const double* const* in, double* const* out) {
            FirstOrderLowPassColumns(rec.t.data(), rec.t.size(), tau, in, out, 3,
                                     rec.restart.data());
          },
          [&](const std::vector<double>& x) {
            return ReferenceFirstOrder(rec.t, x, rec.restart, tau);
          });
      EXPECT_LT(worst, 1e-12) << "tau " << tau;
    }
  }
}

TEST(DiagLowPass, VectorKernelsAgreeWithLibm) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_exp = 0.0;
  double worst_trig = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = -700.0 + 1400.0 * u(rng);
    const double e = lowpass::ExpKernel(x);
    worst_exp = std::max(worst_exp, std::fabs(e - std::exp(x)) / std::exp(x));
    // Angles over the whole range, and many small ones.
    const double th = i % 2 == 0 ? lowpass::kMaxAngle * u(rng) : 4.0 * u(rng);
    double co = 0.0;
    double si = 0.0;
    lowpass::SinCosKernel(th, &co, &si);
    worst_trig = std::max({worst_trig, std::fabs(co - std::cos(th)), std::fabs(si - std::sin(th))});
  }
  EXPECT_LT(worst_exp, 4.5e-16);  // two ulps
  EXPECT_LT(worst_trig, 5e-16);
}

/// A long gappy record (several stream windows): seven GappyRecord clocks end to end, restarts
/// also at a window's first row and the row before it.
Record LongRecord() {
  const Record one = GappyRecord();
  Record rec;
  double offset = 0.0;
  for (int k = 0; k < 7; ++k) {
    for (std::size_t i = 0; i < one.t.size(); ++i) {
      rec.t.push_back(one.t[i] + offset);
      rec.restart.push_back(k > 0 && i == 0 ? 0 : one.restart[i]);
    }
    offset = rec.t.back() + 0.01;
  }
  const std::size_t w = LowPassWindows::kRows;
  rec.restart[w] = 1;
  rec.restart[2 * w + 1] = 1;
  AddInputs(&rec);
  return rec;
}

/// Streams `make(n)` over the first n rows of LongRecord and compares every row with `whole` (the
/// filter's whole columns) bit for bit, for n around the window bounds.
template <class Whole, class Make>
void ExpectStreamIsWhole(const Record& rec, Whole whole, Make make, const std::string& what) {
  const std::size_t w = LowPassWindows::kRows;
  for (std::size_t n : {std::size_t{1}, std::size_t{2}, w, w + 1, w + 2, rec.t.size()}) {
    std::vector<std::vector<double>> ref(3, std::vector<double>(n));
    const double* in[3] = {rec.x[0].data(), rec.x[1].data(), rec.x[2].data()};
    double* out[3] = {ref[0].data(), ref[1].data(), ref[2].data()};
    whole(n, in, out);
    const auto s = make(n, in);
    std::size_t seen = 0;
    int windows = 0;
    while (s->Next()) {
      ASSERT_EQ(s->begin(), seen);
      ++windows;
      for (std::size_t j = 0; j < s->size(); ++j, ++seen) {
        for (std::size_t c = 0; c < 3; ++c) {
          ASSERT_EQ(s->col(c)[j], ref[c][seen]) << what << " n " << n << " row " << seen;
        }
      }
    }
    EXPECT_EQ(seen, n);
    // The first window has w + 1 rows (row 0 and a full window), the others w.
    EXPECT_EQ(windows, static_cast<int>(std::max<std::size_t>(1, (n - 1 + w - 1) / w))) << n;
    EXPECT_FALSE(s->Next());
  }
}

/// Nine columns of distinct inputs on the clock of `rec` (its restarts left out: the columns are
/// then filtered in four-wide vector blocks, and one scalar column).
std::vector<std::vector<double>> NineColumns(Record* rec) {
  rec->restart.assign(rec->t.size(), 0);
  std::vector<std::vector<double>> x(9, std::vector<double>(rec->t.size()));
  for (std::size_t c = 0; c < x.size(); ++c) {
    for (std::size_t i = 0; i < rec->t.size(); ++i) {
      x[c][i] = rec->x[c % 3][i] * (1.0 + 0.1 * static_cast<double>(c)) + 0.01 * (c / 3);
    }
  }
  return x;
}

/// Filters the columns of x at once (`columns`), streamed (`stream`) and each alone (`alone`):
/// every row of every column the same bits three ways, and within `tol` × the input scale of
/// `ref` per column.
template <class Columns, class Stream, class Alone, class Ref>
void ExpectColumnsAreEachAlone(const Record& rec, const std::vector<std::vector<double>>& x,
                               Columns columns, Stream stream, Alone alone, Ref ref, double tol,
                               const std::string& what) {
  const std::size_t n = rec.t.size();
  const std::size_t m = x.size();
  std::vector<const double*> in;
  for (const auto& col : x) in.push_back(col.data());
  std::vector<std::vector<double>> all(m, std::vector<double>(n));
  std::vector<double*> out;
  for (auto& col : all) out.push_back(col.data());
  columns(in.data(), out.data(), m);
  const auto s = stream(in.data(), m);
  while (s->Next()) {
    for (std::size_t c = 0; c < m; ++c) {
      for (std::size_t j = 0; j < s->size(); ++j) {
        ASSERT_EQ(s->col(c)[j], all[c][s->begin() + j]) << what << " streamed, column " << c;
      }
    }
  }
  double scale = 0.0;
  for (const auto& col : x) {
    for (double v : col) scale = std::max(scale, std::fabs(v));
  }
  for (std::size_t c = 0; c < m; ++c) {
    std::vector<double> one(n);
    alone(x[c].data(), one.data());
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(all[c][i], one[i]) << what << " column " << c << " row " << i;
    }
    const std::vector<double> r = ref(x[c]);
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(all[c][i] - r[i]));
    EXPECT_LT(worst, tol * scale) << what << " column " << c;
  }
}

/// A long record on an exactly uniform clock (steps of 2^-10 s).
Record UniformRecord() {
  Record rec = LongRecord();
  for (std::size_t i = 0; i < rec.t.size(); ++i) rec.t[i] = std::ldexp(static_cast<double>(i), -10);
  return rec;
}

// Nine columns at once (two four-wide vector blocks and one scalar column) give each column bit
// for bit what it gives filtered alone (the scalar block), on a jittered clock with gaps and on a
// uniform one, whole and streamed; and the independent reference per column (to 1e-11 of the
// input's scale: the rounding of a slow filter's recursion adds up over these 10 500 rows).
TEST(DiagLowPass, ManyColumnsAreEachColumnAloneBitForBit) {
  for (Record rec : {GappyRecord(), UniformRecord()}) {
    const std::vector<std::vector<double>> x = NineColumns(&rec);
    const double* t = rec.t.data();
    const std::size_t n = rec.t.size();
    for (double tau : {0.003, 0.3, 1000.0}) {
      ExpectColumnsAreEachAlone(
          rec, x,
          [&](const double* const* in, double* const* out, std::size_t m) {
            FirstOrderLowPassColumns(t, n, tau, in, out, m);
          },
          [&](const double* const* in, std::size_t m) {
            return std::make_unique<FirstOrderLowPassStream>(t, n, tau, in, m);
          },
          [&](const double* in, double* out) { FirstOrderLowPass(t, in, n, tau, out); },
          [&](const std::vector<double>& col) {
            return ReferenceFirstOrder(rec.t, col, rec.restart, tau);
          },
          1e-11, "first order tau " + std::to_string(tau));
    }
    for (double zeta : {0.01, 1.0, 1.5}) {
      for (double f : {0.5, 30.0}) {
        ExpectColumnsAreEachAlone(
            rec, x,
            [&](const double* const* in, double* const* out, std::size_t m) {
              SecondOrderLowPassColumns(t, n, f, zeta, in, out, m);
            },
            [&](const double* const* in, std::size_t m) {
              return std::make_unique<SecondOrderLowPassStream>(t, n, f, zeta, in, m);
            },
            [&](const double* in, double* out) { SecondOrderLowPass(t, in, n, f, zeta, out); },
            [&](const std::vector<double>& col) {
              return ReferenceSecondOrder(rec.t, col, rec.restart, f, zeta);
            },
            1e-11, "second order f " + std::to_string(f) + " zeta " + std::to_string(zeta));
      }
    }
  }
}

TEST(DiagLowPass, StreamsGiveTheWholeColumnsBitForBit) {
  const Record rec = LongRecord();
  const std::uint8_t* restart = rec.restart.data();
  for (double tau : {0.003, 0.3, 1000.0}) {
    ExpectStreamIsWhole(
        rec,
        [&](std::size_t n, const double* const* in, double* const* out) {
          FirstOrderLowPassColumns(rec.t.data(), n, tau, in, out, 3, restart);
        },
        [&](std::size_t n, const double* const* in) {
          return std::make_unique<FirstOrderLowPassStream>(rec.t.data(), n, tau, in, 3, restart);
        },
        "first order tau " + std::to_string(tau));
  }
  for (double zeta : {0.01, 1.0, 1.5}) {
    for (double f : {0.5, 30.0}) {
      ExpectStreamIsWhole(
          rec,
          [&](std::size_t n, const double* const* in, double* const* out) {
            SecondOrderLowPassColumns(rec.t.data(), n, f, zeta, in, out, 3, restart);
          },
          [&](std::size_t n, const double* const* in) {
            return std::make_unique<SecondOrderLowPassStream>(rec.t.data(), n, f, zeta, in, 3,
                                                              restart);
          },
          "second order f " + std::to_string(f) + " zeta " + std::to_string(zeta));
    }
  }
}
}  // namespace
}  // namespace ftstack::diag
