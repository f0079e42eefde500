#include "measurement/numerics.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <unsupported/Eigen/FFT>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace ftstack::numerics {

FohSystem DiscretiseFoh(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double h_s) {
  // exp of the augmented matrix [[A h, B h, 0], [0, 0, 1], [0, 0, 0]] holds Φ, Γ1 and Γ2.
  const Eigen::Index n = a.rows();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 2, n + 2);
  m.topLeftCorner(n, n) = a * h_s;
  m.block(0, n, n, 1) = b * h_s;
  m(n, n + 1) = 1.0;
  const Eigen::MatrixXd e = m.exp();
  return {e.topLeftCorner(n, n), e.block(0, n, n, 1), e.block(0, n + 1, n, 1)};
}

FohSystem FirstOrderLagFoh(double tau_s, double h_s) {
  return DiscretiseFoh(Eigen::MatrixXd::Constant(1, 1, -1.0 / tau_s),
                       Eigen::VectorXd::Constant(1, 1.0 / tau_s), h_s);
}

FohSystem SecondOrderFoh(double freq_hz, double damping_ratio, double h_s) {
  const double wn = 2.0 * std::numbers::pi * freq_hz;
  Eigen::MatrixXd a(2, 2);
  a << 0.0, 1.0, -wn * wn, -2.0 * damping_ratio * wn;
  return DiscretiseFoh(a, Eigen::Vector2d(0.0, wn * wn), h_s);
}

std::vector<double> FohResponse(const FohSystem& sys, const Eigen::RowVectorXd& c,
                                Eigen::VectorXd x0, const std::vector<double>& u) {
  std::vector<double> y(u.size());
  if (u.empty()) return y;
  y[0] = c * x0;
  for (std::size_t k = 0; k + 1 < u.size(); ++k) {
    x0 = sys.phi * x0 + sys.gamma1 * u[k] + sys.gamma2 * (u[k + 1] - u[k]);
    y[k + 1] = c * x0;
  }
  return y;
}

void PlayOperator(const double* x, std::size_t n, double width, double* z) {
  if (n == 0) return;
  double p = x[0];
  const double h = 0.5 * width;
  for (std::size_t i = 0; i < n; ++i) {
    p = PlayStep(p, x[i], h);
    z[i] = (p - x[i]) / h;
  }
}

std::size_t WelchSegment(std::size_t n) {
  std::size_t seg = 1024;
  while (seg > 32 && seg * 8 > n) seg /= 2;
  return seg;
}

namespace {

/// Calls each(power) with |FFT|² of every Hann-windowed, linearly detrended segment of x
/// (half-overlapping); fills s's frequencies and counts its segments. Returns the window's Σw² (the
/// periodogram's scale), 0 when x is too short.
double ForWelchSegments(const double* x, std::size_t n, double rate_hz, std::size_t segment,
                        Spectrum* s, const std::function<void(const std::vector<double>&)>& each) {
  if (segment < 8 || n < segment) return 0.0;
  const std::size_t half = segment / 2;
  const auto seg_d = static_cast<double>(segment);
  std::vector<double> win(segment);
  double wsum2 = 0.0;
  for (std::size_t j = 0; j < segment; ++j) {
    win[j] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(j) / seg_d);
    wsum2 += win[j] * win[j];
  }
  s->freq_hz.resize(half + 1);
  for (std::size_t k = 0; k <= half; ++k) s->freq_hz[k] = static_cast<double>(k) * rate_hz / seg_d;
  Eigen::FFT<double> fft;
  std::vector<double> buf(segment);
  std::vector<double> power(half + 1);
  std::vector<std::complex<double>> out;
  // Linear-trend removal: least-squares line over j = 0 … segment − 1, centred at jm.
  const double jm = (seg_d - 1.0) / 2.0;
  double sjj = 0.0;
  for (std::size_t j = 0; j < segment; ++j) {
    sjj += (static_cast<double>(j) - jm) * (static_cast<double>(j) - jm);
  }
  for (std::size_t start = 0; start + segment <= n; start += half) {
    double mean = 0.0;
    double sj = 0.0;
    for (std::size_t j = 0; j < segment; ++j) {
      mean += x[start + j];
      sj += (static_cast<double>(j) - jm) * x[start + j];
    }
    mean /= seg_d;
    const double slope = sj / sjj;
    for (std::size_t j = 0; j < segment; ++j) {
      buf[j] = (x[start + j] - mean - slope * (static_cast<double>(j) - jm)) * win[j];
    }
    fft.fwd(out, buf);
    for (std::size_t k = 0; k <= half; ++k) power[k] = std::norm(out[k]);
    each(power);
    ++s->segments;
  }
  return wsum2;
}

}  // namespace

Spectrum Welch(const double* x, std::size_t n, double rate_hz, std::size_t segment) {
  Spectrum s;
  std::vector<double> sum;
  const double wsum2 =
      ForWelchSegments(x, n, rate_hz, segment, &s, [&](const std::vector<double>& p) {
        if (sum.empty()) sum.assign(p.size(), 0.0);
        for (std::size_t k = 0; k < p.size(); ++k) sum[k] += p[k];
      });
  if (wsum2 == 0.0) return s;
  s.power = std::move(sum);
  for (auto& p : s.power) p /= static_cast<double>(s.segments) * wsum2;
  return s;
}

Spectrum WelchMedian(const double* x, std::size_t n, double rate_hz, std::size_t segment) {
  Spectrum s;
  std::vector<std::vector<double>> all;
  const double wsum2 = ForWelchSegments(x, n, rate_hz, segment, &s,
                                        [&](const std::vector<double>& p) { all.push_back(p); });
  if (wsum2 == 0.0) return s;
  s.power.resize(all.front().size());
  std::vector<double> column(all.size());
  for (std::size_t k = 0; k < s.power.size(); ++k) {
    for (std::size_t q = 0; q < all.size(); ++q) column[q] = all[q][k];
    const auto mid = column.begin() + static_cast<std::ptrdiff_t>(column.size() / 2);
    std::nth_element(column.begin(), mid, column.end());
    s.power[k] = *mid / wsum2;
  }
  return s;
}

double MinimizeOnGrid(const std::function<double(double)>& f, const std::vector<double>& grid,
                      int golden_iterations, double* fmin) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t bi = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const double v = f(grid[i]);
    if (v < best) {
      best = v;
      bi = i;
    }
  }
  double lo = grid[bi > 0 ? bi - 1 : bi];
  double hi = grid[bi + 1 < grid.size() ? bi + 1 : bi];
  double xbest = grid[bi];
  if (golden_iterations > 0 && hi > lo) {
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;  // 1/φ
    double c = hi - g * (hi - lo);
    double d = lo + g * (hi - lo);
    double fc = f(c);
    double fd = f(d);
    for (int it = 0; it < golden_iterations; ++it) {
      if (fc < fd) {  // the minimum lies in [lo, d]
        hi = d;
        d = c;
        fd = fc;
        c = hi - g * (hi - lo);
        fc = f(c);
      } else {  // in [c, hi]
        lo = c;
        c = d;
        fc = fd;
        d = lo + g * (hi - lo);
        fd = f(d);
      }
    }
    if (fc < best) {
      best = fc;
      xbest = c;
    }
    if (fd < best) {
      best = fd;
      xbest = d;
    }
  }
  if (fmin != nullptr) *fmin = best;
  return xbest;
}

}  // namespace ftstack::numerics
