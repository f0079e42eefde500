// Shared pieces of the two pivot formulations: dimensionless strip geometry and validity rules
// (internal).
#pragma once

#include <Eigen/Dense>
#include <array>

#include "sim/pivot/pivot.hpp"

namespace ftstack::sim::pivot::detail {

/// One strip in units of L: direction e, CCW normal n, base end A = −λe, body end offset ρ =
/// (1−λ)e.
struct StripFrame {
  Eigen::Vector2d e, n, base, rho;
  double phi0 = 0.0;  ///< Angle of e from +x (rad).
};

std::array<StripFrame, 2> StripFrames(const PivotGeometry& g);

/// The strips and the load in units of L and EI/L², the common start of both formulations.
struct DimensionlessPivot {
  std::array<StripFrame, 2> strips;
  double theta = 0.0, h = 0.0, v = 0.0;
};
DimensionlessPivot MakeDimensionless(const PivotGeometry& g, const PivotLoad& load);

/// Rotation by theta and its derivative.
Eigen::Matrix2d Rot(double theta);
Eigen::Matrix2d RotDerivative(double theta);

/// 2-D cross product a × b (z component).
inline double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Stress weights: stress (Pa) = |m|·moment_weight + |n|·axial_weight for dimensionless m, n.
struct StressWeights {
  double moment_weight = 0.0, axial_weight = 0.0;
};
StressWeights MakeStressWeights(const PivotGeometry& g);

/// Fills valid/reason from converged, dc_dtheta, max_compression_n and max_stress_pa. Without
/// convergence the numbers become NaN and the reason adds a buckling diagnosis from statics.
void Judge(const PivotGeometry& g, const PivotLoad& load, PivotResult& r);

PivotResult SolveExact(const PivotGeometry& g, const PivotLoad& load, const PivotOptions& options);
PivotResult SolveWittrick(const PivotGeometry& g, const PivotLoad& load,
                          const PivotOptions& options);

}  // namespace ftstack::sim::pivot::detail
