#include "diagnosis/signal.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <unsupported/Eigen/FFT>

namespace ftstack::diag {

std::size_t WelchSegment(std::size_t n) {
  std::size_t seg = 1024;
  while (seg > 32 && seg * 8 > n) seg /= 2;
  return seg;
}

Spectrum Welch(const double* x, std::size_t n, double rate_hz, std::size_t segment) {
  Spectrum s;
  if (segment < 8 || n < segment) return s;
  const std::size_t half = segment / 2;
  std::vector<double> win(segment);
  double wsum2 = 0.0;
  for (std::size_t j = 0; j < segment; ++j) {
    win[j] =
        0.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(j) / static_cast<double>(segment));
    wsum2 += win[j] * win[j];
  }
  s.power.assign(half + 1, 0.0);
  s.freq_hz.resize(half + 1);
  for (std::size_t k = 0; k <= half; ++k) {
    s.freq_hz[k] = static_cast<double>(k) * rate_hz / static_cast<double>(segment);
  }
  Eigen::FFT<double> fft;
  std::vector<double> buf(segment);
  std::vector<std::complex<double>> out;
  // Linear-trend removal: least squares line over j = 0…seg-1.
  const double jm = (static_cast<double>(segment) - 1.0) / 2.0;
  double sjj = 0.0;
  for (std::size_t j = 0; j < segment; ++j)
    sjj += (static_cast<double>(j) - jm) * (static_cast<double>(j) - jm);
  for (std::size_t start = 0; start + segment <= n; start += half) {
    double mean = 0.0;
    double sj = 0.0;
    for (std::size_t j = 0; j < segment; ++j) {
      mean += x[start + j];
      sj += (static_cast<double>(j) - jm) * x[start + j];
    }
    mean /= static_cast<double>(segment);
    const double slope = sj / sjj;
    for (std::size_t j = 0; j < segment; ++j) {
      buf[j] = (x[start + j] - mean - slope * (static_cast<double>(j) - jm)) * win[j];
    }
    fft.fwd(out, buf);
    for (std::size_t k = 0; k <= half; ++k) s.power[k] += std::norm(out[k]);
    ++s.segments;
  }
  for (auto& p : s.power) p /= static_cast<double>(s.segments) * wsum2;
  return s;
}

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

void NormalEq::Add(const double* x, double y, double w) {
  for (int a = 0; a < p_; ++a) {
    const double wa = w * x[a];
    xty_(a) += wa * y;
    for (int b = 0; b <= a; ++b) xtx_(a, b) += wa * x[b];
  }
  yty_ += w * y * y;
  rows_ += 1.0;
}

void NormalEq::AddSparse(const int* idx, const double* val, int nnz, double y, double w) {
  for (int a = 0; a < nnz; ++a) {
    const double wa = w * val[a];
    xty_(idx[a]) += wa * y;
    for (int b = 0; b < nnz; ++b) {
      if (idx[b] <= idx[a]) xtx_(idx[a], idx[b]) += wa * val[b];
    }
  }
  yty_ += w * y * y;
  rows_ += 1.0;
}

NormalEq::Result NormalEq::Solve() const {
  Result r;
  r.rows = rows_;
  Eigen::MatrixXd a = xtx_.selfadjointView<Eigen::Lower>();
  // Jacobi scaling for conditioning; zero columns (features absent) get a unit diagonal.
  Eigen::VectorXd d(p_);
  for (int i = 0; i < p_; ++i) d(i) = a(i, i) > 0 ? 1.0 / std::sqrt(a(i, i)) : 1.0;
  Eigen::MatrixXd as = d.asDiagonal() * a * d.asDiagonal();
  for (int i = 0; i < p_; ++i) as(i, i) += 1e-12;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(as);
  const Eigen::VectorXd bs = ldlt.solve(d.asDiagonal() * xty_);
  r.beta = d.asDiagonal() * bs;
  r.cov_unit = d.asDiagonal() * ldlt.solve(Eigen::MatrixXd::Identity(p_, p_)) * d.asDiagonal();
  r.sse = std::max(0.0, yty_ - r.beta.dot(xty_));
  return r;
}

void FirstOrderLowPass(const double* t_s, const double* x, std::size_t n, double tau_s, double* y) {
  if (n == 0) return;
  y[0] = x[0];
  double last_dt = -1.0;
  double a = 0.0;
  double b0 = 0.0;
  double b1 = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = t_s[i] - t_s[i - 1];
    if (std::fabs(dt - last_dt) > 1e-12) {
      const double r = dt / tau_s;
      a = std::exp(-r);
      const double g = r > 1e-8 ? (1.0 - a) / r : 1.0 - r / 2.0;  // (1 − a)·τ/dt
      b0 = 1.0 - g;
      b1 = g - a;
      last_dt = dt;
    }
    y[i] = a * y[i - 1] + b0 * x[i] + b1 * x[i - 1];
  }
}

namespace {

// exp(M) of a small matrix by scaling and squaring with a Taylor series.
Eigen::Matrix4d Expm(const Eigen::Matrix4d& m) {
  const double norm = m.cwiseAbs().rowwise().sum().maxCoeff();
  int s = 0;
  if (norm > 0.25) s = static_cast<int>(std::ceil(std::log2(norm / 0.25)));
  const Eigen::Matrix4d a = m / std::pow(2.0, s);
  Eigen::Matrix4d term = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d sum = term;
  for (int k = 1; k <= 14; ++k) {
    term = term * a / static_cast<double>(k);
    sum += term;
  }
  for (int i = 0; i < s; ++i) sum = sum * sum;
  return sum;
}

}  // namespace

void SecondOrderLowPass(const double* t_s, const double* x, std::size_t n, double freq_hz,
                        double damping_ratio, double* y) {
  if (n == 0) return;
  const double w = 2.0 * M_PI * freq_hz;
  double pos = x[0];
  double vel = 0.0;
  y[0] = pos;
  double last_dt = -1.0;
  Eigen::Matrix2d phi;
  Eigen::Vector2d g0;
  Eigen::Vector2d g1;
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = t_s[i] - t_s[i - 1];
    if (std::fabs(dt - last_dt) > 1e-12) {
      // State [y, ẏ], input u(τ) = u0 + (u1 − u0)·τ/dt. Augmented [A B 0; 0 0 1/dt; 0 0 0].
      Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
      m(0, 1) = 1.0;
      m(1, 0) = -w * w;
      m(1, 1) = -2.0 * damping_ratio * w;
      m(1, 2) = w * w;
      m(2, 3) = 1.0 / dt;
      const Eigen::Matrix4d e = Expm(m * dt);
      phi = e.block<2, 2>(0, 0);
      g0 = e.block<2, 1>(0, 2);
      g1 = e.block<2, 1>(0, 3);
      last_dt = dt;
    }
    const double u0 = x[i - 1];
    const double du = x[i] - x[i - 1];
    const double np = phi(0, 0) * pos + phi(0, 1) * vel + g0(0) * u0 + g1(0) * du;
    const double nv = phi(1, 0) * pos + phi(1, 1) * vel + g0(1) * u0 + g1(1) * du;
    pos = np;
    vel = nv;
    y[i] = pos;
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

void PlayOperator(const double* x, std::size_t n, double width, double* z) {
  if (n == 0) return;
  double p = x[0];
  const double h = 0.5 * width;
  for (std::size_t i = 0; i < n; ++i) {
    p = std::clamp(p, x[i] - h, x[i] + h);
    z[i] = (p - x[i]) / h;
  }
}

double InterpolateAt(const double* t, const double* x, std::size_t n, double tq, bool uniform) {
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
  double a = grid[bi > 0 ? bi - 1 : bi];
  double b = grid[bi + 1 < grid.size() ? bi + 1 : bi];
  double xbest = grid[bi];
  if (golden_iterations > 0 && b > a) {
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    double c = b - g * (b - a);
    double d = a + g * (b - a);
    double fc = f(c);
    double fd = f(d);
    for (int it = 0; it < golden_iterations; ++it) {
      if (fc < fd) {
        b = d;
        d = c;
        fd = fc;
        c = b - g * (b - a);
        fc = f(c);
      } else {
        a = c;
        c = d;
        fc = fd;
        d = a + g * (b - a);
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

double Correlation(const double* a, const double* b, std::size_t n) {
  if (n < 2) return 0.0;
  double ma = 0.0;
  double mb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0.0;
  double saa = 0.0;
  double sbb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace ftstack::diag
