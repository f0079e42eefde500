// Crossed-strip flexure pivot: geometry, loads, results and the two solvers (exact elastica,
// Wittrick).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

namespace ftstack::sim::pivot {

// ---------------------------------------------------------------------------------------------
// Frame and sign conventions (see docs/pivot.md).
//
//   y is the pivot axis, pointing from the base (below) to the moving body (above); x is across.
//   O is the point where the two strips cross in the unloaded pivot, the origin of the frame.
//   Strip i (i = 1, 2) runs from its base end A_i to its body end B_i along the unit vector
//     e_1 = ( sin alpha, cos alpha),   e_2 = (-sin alpha, cos alpha),
//   with A_i = -lambda·L·e_i and B_i = (1 - lambda)·L·e_i (lambda = 0.5: crossing at midpoints).
//   Both ends are clamped: A_i to the base, B_i to the moving body.
//   The moving body rotates by theta (counter-clockwise positive) and the body point that started
//   at O moves by (dX, dY). Loads applied at that body point: H along +x, V along +y (V > 0 pulls
//   the body away from the base, i.e. puts the strips in tension). C is the couple about that
//   point, counter-clockwise positive, that the outside must apply to hold the body at theta.
//
// Dimensionless strip quantities (EI = E·b·t³/12 of one strip):
//   f_i  = N_i·L²/EI, N_i the axial force of strip i at its body end B_i, tension positive
//          (exact solver: the component of the end force along the deformed tangent at B_i;
//          Wittrick: the component along the undeformed strip axis e_i).
//   mB_i = M_Bi·L/EI, M_Bi the bending moment the moving body applies to strip i at B_i,
//          counter-clockwise positive (in pure rotation both are ≈ +theta·EI/L at lambda = 0.5).
// ---------------------------------------------------------------------------------------------

/// Material and geometry of the pivot. Defaults: the seed report's strip, crossing at 90°.
struct PivotGeometry {
  double e_pa = 200e9;                    ///< Young's modulus (Pa).
  double length_m = 0.098;                ///< Free length L of each strip (m).
  double width_m = 0.013;                 ///< Width b of each strip (m).
  double thickness_m = 0.5e-3;            ///< Thickness t of each strip (m).
  double alpha_rad = 0.7853981633974483;  ///< Angle of each strip from the pivot axis (rad).
  double crossing_fraction = 0.5;  ///< lambda: the strips cross at lambda·L from their base end.
  /// Yield strength (Pa). Default 1.0 GPa: a conservative figure for hardened carbon spring-steel
  /// strip (EN 10132-4 C75S / AISI 1075 tempered, Rp0.2 typically 1.0–1.6 GPa).
  double yield_pa = 1.0e9;

  /// E·b·t³/12 of one strip (N·m²).
  [[nodiscard]] double BendingStiffness() const;
  /// Euler load of one strip clamped at both ends without sway, 4·pi²·EI/L² (N). The moving body
  /// cannot sway sideways without stretching the other strip, so a strip buckles between clamps.
  [[nodiscard]] double EulerLoad() const;
};

/// Prescribed rotation and the dead loads at the moving body's reference point.
struct PivotLoad {
  double theta_rad = 0.0;  ///< Rotation of the moving body, counter-clockwise positive (rad).
  double v_n = 0.0;        ///< Load along the pivot axis, + away from the base (N).
  double h_n = 0.0;        ///< Load across the pivot axis, +x (N).
};

enum class PivotMethod {
  kExact,     ///< Inextensible elastica of each strip, solved by shooting (the reference).
  kWittrick,  ///< Beam-column strips with second-order axial compatibility (Wittrick 1951).
};

struct PivotOptions {
  int max_iterations = 400;     ///< Newton iterations allowed in total (all continuation steps).
  double tolerance = 1e-11;     ///< Max-norm of the dimensionless residual at convergence.
  int integration_steps = 200;  ///< RK4 steps along each strip (exact solver).
  bool want_shape = false;  ///< Fill PivotResult::shape_m (integration_steps + 1 points per strip).
};

struct PivotResult {
  PivotMethod method = PivotMethod::kExact;
  double c_nm = 0.0;           ///< Couple holding theta (N·m), counter-clockwise positive.
  double dx_m = 0.0;           ///< Displacement of the body reference point across the axis (m).
  double dy_m = 0.0;           ///< Displacement along the axis, + away from the base (m).
  std::array<double, 2> f{};   ///< Dimensionless axial forces f_i (see above).
  std::array<double, 2> mb{};  ///< Dimensionless body-end moments mB_i (see above).
  std::array<double, 2> axial_n{};      ///< N_i (N), tension positive.
  std::array<double, 2> moment_b_nm{};  ///< M_Bi (N·m).
  double dc_dtheta_nm_per_rad = 0.0;    ///< Rotational stiffness at the solution (N·m/rad).
  double max_stress_pa = 0.0;           ///< max over both strips of 6|M|/(b t²) + |N|/(b t).
  double max_compression_n = 0.0;       ///< Largest compressive axial force in either strip (N).
  double strain_energy_j = 0.0;         ///< Bending energy of both strips (J); exact solver only.
  int iterations = 0;                   ///< Newton iterations used (all continuation steps).
  bool converged = false;
  bool valid = false;
  std::string reason;  ///< Empty when valid; otherwise every failed rule, separated by "; ".
  /// Deformed centre lines (m, frame above), base end first; filled if options.want_shape.
  std::array<std::vector<Eigen::Vector2d>, 2> shape_m;
};

/// Throws std::invalid_argument (one line) unless every number is finite and physical:
/// E, L, b, t, yield > 0, 0 < alpha < 90°, 0 < lambda < 1, |theta| < 90°, finite loads.
void ValidateInputs(const PivotGeometry& g, const PivotLoad& load);

/// Solves the pivot with the chosen formulation; never throws for valid inputs (non-convergence
/// gives valid = false and NaN numbers). Throws std::invalid_argument for invalid inputs.
[[nodiscard]] PivotResult SolvePivot(const PivotGeometry& g, const PivotLoad& load,
                                     PivotMethod method, const PivotOptions& options = {});

/// The formulation `ftsim pivot` uses unless told otherwise (the one that meets the 2 % rule).
inline constexpr PivotMethod kDefaultPivotMethod = PivotMethod::kExact;

[[nodiscard]] const char* ToString(PivotMethod m);

// ----- Building blocks, exposed for tests --------------------------------------------------------

/// End state of one strip integrated as an inextensible elastica in dimensionless form
/// (arc length s in [0, 1] in units of L, moments in EI/L, forces in EI/L²).
struct ElasticaEnd {
  double phi = 0.0, m = 0.0, x = 0.0, y = 0.0;  ///< Tangent angle, moment, position at s = 1.
  Eigen::Matrix<double, 4, 3> sensitivity;      ///< d(phi, m, x, y)(1) / d(m0, fx, fy).
  double max_abs_m = 0.0;                       ///< max |m(s)|.
  double max_abs_n = 0.0;                       ///< max |n(s)| (axial force, tension positive).
  double max_stress_index = 0.0;  ///< max over s of |m|·mw + |n|·nw (weights set by the caller).
  double max_compression = 0.0;   ///< max over s of -n(s) (0 if always in tension).
  double energy = 0.0;            ///< Bending energy ½∫m² ds (units of EI/L).
};

/// Integrates phi' = m, m' = fx·sin(phi) − fy·cos(phi), x' = cos(phi), y' = sin(phi) from s = 0
/// (phi0, m0, x0, y0) with constant end force (fx, fy) (the force the body end receives), using
/// `steps` RK4 steps, with the sensitivity to (m0, fx, fy). `m_weight`/`n_weight` form the stress
/// index; `shape` (if not null) receives (x, y) at every step.
[[nodiscard]] ElasticaEnd IntegrateElastica(double phi0, double m0, double x0, double y0, double fx,
                                            double fy, int steps, double m_weight = 0.0,
                                            double n_weight = 0.0,
                                            std::vector<Eigen::Vector2d>* shape = nullptr);

/// Beam-column strip (Wittrick): lateral deflection w(s) of a strip clamped at s = 0, with end
/// deflection w1 and end slope theta at s = 1, under axial tension p (all dimensionless, p =
/// P·L²/EI).
struct BeamColumnEnd {
  double m_b = 0.0;         ///< Moment at the body end, w''(1).
  double q = 0.0;           ///< Transverse end force (along the strip's normal n_i) on the strip.
  double shortening = 0.0;  ///< ½∫ w'² ds: axial approach of the ends due to bending.
  double max_abs_m = 0.0;   ///< max |w''(s)| (0 unless asked for).
  bool singular = false;    ///< True at a clamped–clamped buckling load (system singular).
};
[[nodiscard]] BeamColumnEnd SolveBeamColumn(double p, double w1, double theta,
                                            bool with_max_moment = true);

}  // namespace ftstack::sim::pivot
