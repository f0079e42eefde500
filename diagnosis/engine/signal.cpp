#include "diagnosis/engine/signal.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <unsupported/Eigen/FFT>

namespace ftstack::diag {

double RobustNoise(const double* x, std::size_t n, double rate_hz) {
  const std::size_t seg = WelchSegment(n);
  if (n < seg || seg < 32) {
    // Too short for a spectrum: MAD of first differences.
    std::vector<double> d;
    for (std::size_t i = 1; i < n; ++i) d.push_back(std::fabs(x[i] - x[i - 1]));
    if (d.empty()) return 0.0;
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    return d[d.size() / 2] / 0.6745 / std::sqrt(2.0);
  }
  const Spectrum s = Welch(x, n, rate_hz, seg);
  const std::size_t half = seg / 2;
  const auto k0 = static_cast<std::size_t>(std::ceil(0.05 * static_cast<double>(half)));
  const auto k1 = static_cast<std::size_t>(std::floor(0.95 * static_cast<double>(half)));
  std::vector<double> band(
      s.power.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(k0, 1)),
      s.power.begin() + static_cast<std::ptrdiff_t>(k1 + 1));
  std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2),
                   band.end());
  const double med = band[band.size() / 2];
  // Each bin ~ σ²·χ²_ν/ν with ν ≈ 2 × (independent segments); Hann at 50 % overlap keeps ~95 %.
  const double nu = std::max(2.0, 2.0 * 0.95 * static_cast<double>(s.segments));
  const double med_ratio = std::pow(1.0 - 2.0 / (9.0 * nu), 3.0);
  return std::sqrt(std::max(0.0, med / med_ratio));
}

NormalEq::NormalEq(int p)
    : p_(p), xtx_(Eigen::MatrixXd::Zero(p, p)), xty_(Eigen::VectorXd::Zero(p)) {}

// XᵀWX is kept in its upper triangle, column a holding rows b ≤ a: the inner loop then walks
// contiguous memory (column-major) and vectorises. Each element receives the same products in
// the same row order as before, so the sums are bit for bit those of the lower-triangle form.
void NormalEq::AddWide(const double* x, double y, double w) { AddUpper<0>(x, y, w); }

NormalEq NormalEq::Leading(int k) const {
  NormalEq e(k);
  e.xtx_ = xtx_.topLeftCorner(k, k);
  e.xty_ = xty_.head(k);
  e.yty_ = yty_;
  e.rows_ = rows_;
  return e;
}

NormalEq::Result NormalEq::Solve() const {
  Result r;
  r.rows = rows_;
  Eigen::MatrixXd a = xtx_.selfadjointView<Eigen::Upper>();
  // Jacobi scaling for conditioning; zero columns (features absent) get a unit diagonal.
  Eigen::VectorXd d(p_);
  for (int i = 0; i < p_; ++i) d(i) = a(i, i) > 0 ? 1.0 / std::sqrt(a(i, i)) : 1.0;
  Eigen::MatrixXd as = d.asDiagonal() * a * d.asDiagonal();
  for (int i = 0; i < p_; ++i) as(i, i) += 1e-12;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(as);
  const Eigen::VectorXd beta_scaled = ldlt.solve(d.asDiagonal() * xty_);
  r.beta = d.asDiagonal() * beta_scaled;
  r.cov_unit = d.asDiagonal() * ldlt.solve(Eigen::MatrixXd::Identity(p_, p_)) * d.asDiagonal();
  r.sse = std::max(0.0, yty_ - r.beta.dot(xty_));
  return r;
}

void MidQuantiles(std::vector<double>* v, int levels, double* level) {
  const auto n = static_cast<double>(v->size() - 1);
  auto from = v->begin();
  for (int k = 0; k < levels; ++k) {
    const auto at = v->begin() + static_cast<std::ptrdiff_t>((k + 0.5) / levels * n);
    if (at >= from) {
      std::nth_element(from, at, v->end());
      from = at + 1;
    }
    level[k] = *at;
  }
}

void DahlOperator(const double* x, std::size_t n, double width, double* z) {
  if (n == 0) return;
  double zz = 0.0;
  z[0] = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    const double dx = x[i] - x[i - 1];
    if (dx != 0.0) {
      const double target = dx > 0 ? 1.0 : -1.0;
      zz = target + (zz - target) * std::exp(-std::fabs(dx) / width);
    }
    z[i] = zz;
  }
}

double InterpolateAt(const double* t, const double* x, std::size_t n, double tq, bool uniform) {
  return InterpolateNear(t, x, n, tq, uniform, n);
}

double InterpolateNear(const double* t, const double* x, std::size_t n, double tq, bool uniform,
                       std::size_t guess) {
  if (n == 0) return 0.0;
  if (tq <= t[0]) return x[0];
  if (tq >= t[n - 1]) return x[n - 1];
  std::size_t i = 0;
  if (uniform) {
    const double h = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
    i = static_cast<std::size_t>((tq - t[0]) / h);
    if (i >= n - 1) i = n - 2;
    while (i > 0 && t[i] > tq) --i;
    while (i + 2 < n && t[i + 1] <= tq) ++i;
  } else if (guess < n) {
    // The same interval as the binary search below (t strictly increasing, t[0] < tq < t[n−1]):
    // the last i with t[i] ≤ tq, walked to from the guess.
    i = std::min(guess, n - 2);
    while (i > 0 && t[i] > tq) --i;
    while (i + 2 < n && t[i + 1] <= tq) ++i;
  } else {
    i = static_cast<std::size_t>(std::upper_bound(t, t + n, tq) - t) - 1;
  }
  const double h = t[i + 1] - t[i];
  const double u = (tq - t[i]) / h;
  if (!uniform || i == 0 || i + 2 >= n) return x[i] + u * (x[i + 1] - x[i]);
  const double p0 = x[i - 1];
  const double p1 = x[i];
  const double p2 = x[i + 1];
  const double p3 = x[i + 2];
  return p1 + 0.5 * u *
                  (p2 - p0 +
                   u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)));
}

namespace {

template <class T>
double CorrelationOf(const T* a, const T* b, std::size_t n) {
  if (n < 2) return 0.0;
  double ma = 0.0;
  double mb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += static_cast<double>(a[i]);
    mb += static_cast<double>(b[i]);
  }
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0.0;
  double saa = 0.0;
  double sbb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double da = static_cast<double>(a[i]) - ma;
    const double db = static_cast<double>(b[i]) - mb;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

double Correlation(const double* a, const double* b, std::size_t n) {
  return CorrelationOf(a, b, n);
}

double Correlation(const float* a, const float* b, std::size_t n) { return CorrelationOf(a, b, n); }

}  // namespace ftstack::diag
