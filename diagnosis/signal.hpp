// Numerical building blocks of the diagnosis: spectra, robust noise, least squares, filters, 1-D
// searches.
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
  void Add(const double* x, double y, double w = 1.0);
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
  int p_;
  Eigen::MatrixXd xtx_;
  Eigen::VectorXd xty_;
  double yty_ = 0.0;
  double rows_ = 0.0;
};

/// First-order low pass with unit DC gain and time constant tau_s, exact for inputs linear
/// between samples; starts at rest at the first input value.
void FirstOrderLowPass(const double* t_s, const double* x, std::size_t n, double tau_s, double* y);

/// The same for m columns x[c] → y[c] on one clock, each row with its own dt: the step coefficients
/// are computed once per row for all columns, for chunks of rows in vectorized loops (lowpass1.cpp;
/// once for a uniform clock). Where restart[i] != 0 (restart may be nullptr) the filter starts
/// again at rest at x[i] (a new recording begins there).
void FirstOrderLowPassColumns(const double* t_s, std::size_t n, double tau_s,
                              const double* const* x, double* const* y, std::size_t m,
                              const std::uint8_t* restart = nullptr);
/// A filter's output over the rows window by window, for consumers that read every row once
/// (memory: kRows rows per column instead of n; the same bits as the filter's whole columns):
///   FirstOrderLowPassStream s(t, n, tau, x, m, restart);
///   while (s.Next()) for (j = 0; j < s.size(); ++j) … s.col(c)[j] is row s.begin() + j …
class LowPassWindows {
 public:
  /// Rows per window after the first (which has one more: row 0); a multiple of the filters'
  /// coefficient chunks, so that the windows compute the coefficients over the same rows.
  static constexpr std::size_t kRows = 4096;
  virtual ~LowPassWindows() = default;
  LowPassWindows(const LowPassWindows&) = delete;
  LowPassWindows& operator=(const LowPassWindows&) = delete;
  /// Filters the next window of rows; false after the last.
  [[nodiscard]] bool Next();
  /// First row of the current window, and its number of rows.
  [[nodiscard]] std::size_t begin() const { return begin_; }
  [[nodiscard]] std::size_t size() const { return size_; }
  /// Column c's output over the window: col(c)[j] is row begin() + j.
  [[nodiscard]] const double* col(std::size_t c) const { return y_[c] + 1; }

 protected:
  LowPassWindows(const double* t_s, std::size_t n, const double* const* x, std::size_t m,
                 const std::uint8_t* restart);
  /// Rows [i_begin, i_end) (i_begin ≥ 1) into y()[c][i − y_off]; row i_begin − 1 is at
  /// y()[c][i_begin − 1 − y_off] (the output's last row, slot 0 of the window).
  virtual void FilterRows(std::size_t i_begin, std::size_t i_end, std::ptrdiff_t y_off) = 0;
  /// The filter starts at rest at row 0 (its output there, x[c][0], is written already).
  virtual void Start() {}
  const double* t_s_;
  std::size_t n_;
  std::vector<const double*> x_;
  const std::uint8_t* restart_;
  std::vector<double*> y_;

 private:
  std::vector<double> buf_;
  std::size_t next_ = 0;
  std::size_t begin_ = 0;
  std::size_t size_ = 0;
};

/// FirstOrderLowPassColumns window by window (LowPassWindows).
class FirstOrderLowPassStream : public LowPassWindows {
 public:
  FirstOrderLowPassStream(const double* t_s, std::size_t n, double tau_s, const double* const* x,
                          std::size_t m, const std::uint8_t* restart = nullptr);
  ~FirstOrderLowPassStream() override;

 private:
  void FilterRows(std::size_t i_begin, std::size_t i_end, std::ptrdiff_t y_off) override;
  struct Coefficients;
  double tau_s_;
  std::unique_ptr<Coefficients> k_;
};

/// Second-order low pass ÿ + 2ζω ẏ + ω² y = ω² x (ω = 2π·freq_hz), unit DC gain, exact for inputs
/// linear between samples; starts at rest at the first input value.
void SecondOrderLowPass(const double* t_s, const double* x, std::size_t n, double freq_hz,
                        double damping_ratio, double* y);

/// The same for m columns on one clock, each row with its own dt (coefficients once per row, for
/// chunks of rows in vectorized loops: lowpass2.cpp), with restarts as FirstOrderLowPassColumns.
void SecondOrderLowPassColumns(const double* t_s, std::size_t n, double freq_hz,
                               double damping_ratio, const double* const* x, double* const* y,
                               std::size_t m, const std::uint8_t* restart = nullptr);
/// SecondOrderLowPassColumns window by window (LowPassWindows).
class SecondOrderLowPassStream : public LowPassWindows {
 public:
  SecondOrderLowPassStream(const double* t_s, std::size_t n, double freq_hz, double damping_ratio,
                           const double* const* x, std::size_t m,
                           const std::uint8_t* restart = nullptr);
  ~SecondOrderLowPassStream() override;

 private:
  void FilterRows(std::size_t i_begin, std::size_t i_end, std::ptrdiff_t y_off) override;
  void Start() override;
  struct State;
  std::unique_ptr<State> st_;
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

/// Pearson correlation of two equally long series.
[[nodiscard]] double Correlation(const double* a, const double* b, std::size_t n);

}  // namespace ftstack::diag
