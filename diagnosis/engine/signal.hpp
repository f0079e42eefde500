// Numerical building blocks of the diagnosis: spectra, robust noise, least squares, the Dahl
// operator, interpolation, correlation (the filters are in diagnosis/filters/).
#pragma once

#include <Eigen/Dense>
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
  /// Adds row x (p features), target y, weight w. Inline with the one- and two-feature rows
  /// written out: the searches add tens of millions of those per diagnosis, where a call and a
  /// loop cost more than the sums. Every element receives the same products in the same order
  /// for any p.
  // GCC's -Warray-bounds reads the two-feature branch inlined at a caller whose row is one double
  // (p_ = 1 there at run time, so the branch is never taken).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
  void Add(const double* x, double y, double w = 1.0) {
    double* const xtx = xtx_.data();
    double* const xty = xty_.data();
    if (p_ == 1) {
      const double wa = w * x[0];
      xty[0] += wa * y;
      xtx[0] += wa * x[0];
    } else if (p_ == 2) {
      const double w0 = w * x[0];
      xty[0] += w0 * y;
      xtx[0] += w0 * x[0];
      const double w1 = w * x[1];
      xty[1] += w1 * y;
      xtx[2] += w1 * x[0];
      xtx[3] += w1 * x[1];
    } else {
      AddWide(x, y, w);
    }
    yty_ += w * y * y;
    rows_ += 1.0;
  }
#pragma GCC diagnostic pop
  /// Row with only `nnz` non-zero features at indices idx.
  void AddSparse(const int* idx, const double* val, int nnz, double y, double w = 1.0);
  struct Result {
    Eigen::VectorXd beta;
    Eigen::MatrixXd cov_unit;  ///< (XᵀWX)⁻¹; times the residual variance gives the covariance
    double sse = 0.0;          ///< weighted residual sum of squares
    double rows = 0.0;
  };
  [[nodiscard]] Result Solve() const;
  [[nodiscard]] int p() const { return p_; }

 private:
  /// The upper triangle's and XᵀWy's sums of Add for any p.
  void AddWide(const double* x, double y, double w);

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
