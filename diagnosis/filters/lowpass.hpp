// Closed-form low passes of the diagnosis (first and second order), exact for inputs linear between
// samples on any clock: whole columns, or window by window as streams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace ftstack::diag {

/// First-order low pass with unit DC gain and time constant tau_s, exact for inputs linear
/// between samples; starts at rest at the first input value.
void FirstOrderLowPass(const double* t_s, const double* x, std::size_t n, double tau_s, double* y);

/// The same for m columns x[c] → y[c] on one clock, each row with its own dt: the step coefficients
/// are computed once per row for all columns, for chunks of rows in vectorized loops
/// (first_order.cpp; once for a uniform clock). Where restart[i] != 0 (restart may be nullptr) the
/// filter starts again at rest at x[i] (a new recording begins there).
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
/// chunks of rows in vectorized loops: second_order.cpp), with restarts as
/// FirstOrderLowPassColumns.
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

}  // namespace ftstack::diag
