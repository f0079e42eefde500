// The real record's converter resolution: the step of its value grid per bridge, declared by the
// recording or inferred from the values, and the size of effect such a grid could show.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <string>

#include "diagnosis/loader/data.hpp"

namespace ftstack::diag {

/// The grid the real bridges' values lie on.
struct Quantisation {
  Eigen::VectorXd step_mvv;  ///< per channel, mV/V; 0 where the values lie on no visible grid
  std::string source;        ///< "declared" (the converter's code step), "inferred", or ""

  [[nodiscard]] bool quantised() const { return step_mvv.size() > 0 && step_mvv.maxCoeff() > 0; }
};

/// An effect whose prediction's RMS on the fitted rows stays within this many steps of the grid
/// on every channel is not claimed. Below about 3 steps an undithered grid's rounding error (a
/// deterministic function of the true value, within ±½ step on every held load, RMS 0.29 step)
/// lets a few parameters per channel fit the per-load rounding of a record with noise below one
/// step: a smooth function of the load, a slow drift, matches it as well as a real effect would.
inline constexpr double kResolvableSteps = 3.0;

/// Rows of a channel sampled to infer its grid (evenly strided; the sort stays cheap on 10^6 rows).
inline constexpr std::size_t kGridSampleRows = 20000;

/// The step of the grid `n` values lie on, or 0 when none is visible: the sampled values' distinct
/// levels are at most a quarter of the samples (values repeat), and the smallest gap between
/// neighbouring levels divides ≥ 99 % of the levels' distances from the lowest one to within 5 %
/// of a step.
[[nodiscard]] double InferGridStep(const double* values, std::size_t n);

/// The real bridges' grid: the declared converter's step (a recording in counts with a known
/// scale, recording-format.md) on every channel, else the grid inferred from each channel's
/// values. Needs d.real_mvv.
[[nodiscard]] Quantisation FindQuantisation(const DiagData& d);

}  // namespace ftstack::diag
