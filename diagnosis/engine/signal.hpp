// Numerical building blocks of the diagnosis: spectra, robust noise, least squares, the Dahl
// operator, interpolation, correlation (the filters are in diagnosis/filters/).
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "measurement/numerics.hpp"

namespace ftstack::diag {

// Spectra, the play operator and the 1-D search are the shared numerics (measurement/numerics).
using numerics::MinimizeOnGrid;
using numerics::PlayOperator;
using numerics::Spectrum;
using numerics::Welch;
using numerics::WelchSegment;

/// White-noise σ of x from the median Welch level over 5 %…95 % of the Nyquist band (robust to
/// slow effects and to narrow lines), corrected for the median of the χ² averaging distribution.
[[nodiscard]] double RobustNoise(const double* x, std::size_t n, double rate_hz);

/// Weighted linear least squares by normal equations, accumulated row by row.
class NormalEq {
 public:
  explicit NormalEq(int p);
  /// Adds row x (p features), target y, weight w. Inline, with rows of up to four features
  /// unrolled: the searches add tens of millions of those per diagnosis, where a call and a loop
  /// cost more than the sums. Every element receives the same products in the same order for any
  /// p.
  // GCC's -Warray-bounds reads a wider branch inlined at a caller whose row is shorter (p_ is
  // that row's length at run time, so the branch is never taken).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
  void Add(const double* x, double y, double w = 1.0) {
    switch (p_) {
      case 1:
        AddUpper<1>(x, y, w);
        break;
      case 2:
        AddUpper<2>(x, y, w);
        break;
      case 3:
        AddUpper<3>(x, y, w);
        break;
      case 4:
        AddUpper<4>(x, y, w);
        break;
      default:
        AddWide(x, y, w);
    }
    yty_ += w * y * y;
    rows_ += 1.0;
  }
#pragma GCC diagnostic pop
  /// Row with only `nnz` non-zero features at indices idx (inline: the callers' nnz is a
  /// constant, and the loops unroll).
  void AddSparse(const int* idx, const double* val, int nnz, double y, double w = 1.0) {
    for (int a = 0; a < nnz; ++a) {
      const double wa = w * val[a];
      xty_(idx[a]) += wa * y;
      for (int b = 0; b < nnz; ++b) {
        if (idx[b] <= idx[a]) xtx_(idx[b], idx[a]) += wa * val[b];
      }
    }
    yty_ += w * y * y;
    rows_ += 1.0;
  }
  struct Result {
    Eigen::VectorXd beta;
    Eigen::MatrixXd cov_unit;  ///< (XᵀWX)⁻¹; times the residual variance gives the covariance
    double sse = 0.0;          ///< weighted residual sum of squares
    double rows = 0.0;
  };
  [[nodiscard]] Result Solve() const;
  [[nodiscard]] int p() const { return p_; }
  /// The sums of the rows' first k ≤ p features alone: bit for bit what Add of those k features
  /// would have summed (every element gets the same products in the same order), without a
  /// second pass.
  [[nodiscard]] NormalEq Leading(int k) const;

 private:
  /// The upper triangle's and XᵀWy's sums of Add for any p (AddUpper<0>, out of line).
  void AddWide(const double* x, double y, double w);
  /// XᵀWX's upper triangle (column a holding rows b ≤ a) and XᵀWy of one row: p = P known at
  /// compile time (the loops unroll), or P = 0 for p_ at run time.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
  template <int P>
  void AddUpper(const double* x, double y, double w) {
    double* const xtx = xtx_.data();
    double* const xty = xty_.data();
    const std::ptrdiff_t p = P > 0 ? P : p_;
    for (std::ptrdiff_t a = 0; a < p; ++a) {
      const double wa = w * x[a];
      xty[a] += wa * y;
      double* __restrict col = xtx + a * p;
      for (std::ptrdiff_t b = 0; b <= a; ++b) col[b] += wa * x[b];
    }
  }
#pragma GCC diagnostic pop

  int p_;
  Eigen::MatrixXd xtx_;
  Eigen::VectorXd xty_;
  double yty_ = 0.0;
  double rows_ = 0.0;
};

/// Rate-independent first-order hysteresis operator (Dahl type) of x with characteristic travel
/// width: z moves toward sign(dx) by 1 − exp(−|dx|/width) per step; starts at 0. Output in [−1, 1].
void DahlOperator(const double* x, std::size_t n, double width, double* z);

/// Value of a sampled signal at time tq (cubic Catmull-Rom on uniform grids, else linear; clamped
/// at the ends). t must be increasing.
[[nodiscard]] double InterpolateAt(const double* t, const double* x, std::size_t n, double tq,
                                   bool uniform);
/// The same, with a guess of the row at or just below tq (guess ≥ n: none): on a non-uniform
/// clock the interval is walked to from the guess instead of searched, for queries near a row.
[[nodiscard]] double InterpolateNear(const double* t, const double* x, std::size_t n, double tq,
                                     bool uniform, std::size_t guess);

/// The values at sorted positions ⌊(k + ½)/levels · (n − 1)⌋, k = 0 … levels − 1, of *v (n ≥ 1
/// values; reordered) into level[k]: exactly those of a full sort, selected (nth_element) each in
/// what the previous leaves above it.
void MidQuantiles(std::vector<double>* v, int levels, double* level);

/// Pearson correlation of two equally long series.
[[nodiscard]] double Correlation(const double* a, const double* b, std::size_t n);
/// The same of single-precision series, each value widened to double (the same sums, in the same
/// order, as Correlation of their double copies).
[[nodiscard]] double Correlation(const float* a, const float* b, std::size_t n);

}  // namespace ftstack::diag
