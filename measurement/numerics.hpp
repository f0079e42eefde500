// Shared numerics of the host layers: LTI discretisation, play operator, spectra, 1-D search.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <functional>
#include <vector>

namespace ftstack::numerics {

/// Exact discretisation of a linear system ẋ = A·x + B·u for an input linear between samples
/// (first-order hold): x[k+1] = Φ·x[k] + Γ1·u[k] + Γ2·(u[k+1] − u[k]).
struct FohSystem {
  Eigen::MatrixXd phi, gamma1, gamma2;
};
[[nodiscard]] FohSystem DiscretiseFoh(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                      double h_s);

/// First-order lag ẋ = (u − x)/tau_s (unit DC gain) sampled every h_s, first-order hold.
[[nodiscard]] FohSystem FirstOrderLagFoh(double tau_s, double h_s);

/// Second-order low pass ÿ + 2ζω ẏ + ω² y = ω² u (ω = 2π·freq_hz, unit DC gain), state (y, ẏ),
/// sampled every h_s, first-order hold.
[[nodiscard]] FohSystem SecondOrderFoh(double freq_hz, double damping_ratio, double h_s);

/// Output y[k] = c·x[k] of `sys` driven by u (one value per sample) from the state x0 at u[0].
[[nodiscard]] std::vector<double> FohResponse(const FohSystem& sys, const Eigen::RowVectorXd& c,
                                              Eigen::VectorXd x0, const std::vector<double>& u);

/// One step of the play (backlash) operator of half width h: the play p follows x only once x
/// has moved h past it. Returns the new p.
[[nodiscard]] inline double PlayStep(double p, double x, double half_width) {
  return p < x - half_width ? x - half_width : (p > x + half_width ? x + half_width : p);
}

/// Play operator of x with total width `width`, scaled to [−1, 1]: z = 2·(p − x)/width, p as in
/// PlayStep with p = x[0] at the start (centred).
void PlayOperator(const double* x, std::size_t n, double width, double* z);

/// Welch power spectrum (Hann, 50 % overlap, linear detrend per segment) of x sampled at rate_hz.
/// power[k] is the mean |X_k|² / Σw² over segments, so white noise of variance σ² gives σ² in
/// every bin; freq_hz[k] = k·rate/segment for k = 0 … segment/2.
struct Spectrum {
  std::vector<double> freq_hz;
  std::vector<double> power;
  int segments = 0;
};
[[nodiscard]] Spectrum Welch(const double* x, std::size_t n, double rate_hz, std::size_t segment);
/// The same periodograms, their median per bin instead of their mean: the spectrum of the record's
/// typical segment, which a few transients (load steps) do not lift. Not scaled to a density's
/// mean (the median of a χ²₂ periodogram is ln 2 of its mean); for lines against their neighbours.
[[nodiscard]] Spectrum WelchMedian(const double* x, std::size_t n, double rate_hz,
                                   std::size_t segment);

/// The segment length used for a record of n rows: a power of two ≤ 1024 giving ≥ 8 segments.
[[nodiscard]] std::size_t WelchSegment(std::size_t n);

/// Minimises f over a grid, then refines with golden-section search between the best point's
/// neighbours. Returns the argument; *fmin (if not null) receives the value.
double MinimizeOnGrid(const std::function<double(double)>& f, const std::vector<double>& grid,
                      int golden_iterations, double* fmin);

}  // namespace ftstack::numerics
