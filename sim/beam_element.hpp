// 3-D frame element (Euler–Bernoulli or Timoshenko): rectangular section properties and the
// 12-DOF stiffness matrix.
#pragma once

#include <Eigen/Dense>

namespace ftstack::sim {

/// Cross-section and material of a straight prismatic beam (SI units: Pa, m², m⁴).
/// Local axes: x along the beam, y and z the principal axes of the section.
struct BeamSection {
  double e_pa = 0;  ///< Young's modulus
  double g_pa = 0;  ///< shear modulus
  double area_m2 = 0;
  double iy_m4 = 0;  ///< second moment about local y (bending in the x–z plane, deflection w)
  double iz_m4 = 0;  ///< second moment about local z (bending in the x–y plane, deflection v)
  double j_m4 = 0;   ///< Saint-Venant torsion constant
  /// Shear correction factor κ (shear area κ·A) for Timoshenko elements; 5/6 for a rectangle.
  double shear_factor = 5.0 / 6.0;
};

/// Torsion constant of a solid rectangle with sides long_m ≥ short_m:
/// J = a·b³·[1/3 − 0.21·(b/a)·(1 − b⁴/(12·a⁴))] (Roark, Table 10.7 case 4; error < 0.5 %).
[[nodiscard]] double RectangleTorsionConstant(double long_m, double short_m);

/// Rectangular section of width width_m along local y and height height_m along local z;
/// G = E / (2·(1 + ν)). Throws std::invalid_argument on non-positive or non-finite input.
[[nodiscard]] BeamSection RectangularSection(double e_pa, double poisson, double width_m,
                                             double height_m);

/// 12-DOF element stiffness in local coordinates. DOF order: node 1 (ux uy uz rx ry rz), node 2
/// (ux uy uz rx ry rz); translations in m, rotations in rad; forces N, moments N·m. Entries are the
/// exact end stiffnesses of an Euler–Bernoulli beam with no shear deformation (Przemieniecki 1968).
[[nodiscard]] Eigen::Matrix<double, 12, 12> FrameElementStiffness(const BeamSection& s,
                                                                  double length_m);

/// The same element with shear deformation (Timoshenko; Przemieniecki 1968, §5.6): per bending
/// plane Φ = 12·E·I/(κ·G·A·L²), lateral terms ÷ (1 + Φ), diagonal rotation terms (4 + Φ)/(1 + Φ),
/// coupling rotation terms (2 − Φ)/(1 + Φ). Φ → 0 recovers FrameElementStiffness.
[[nodiscard]] Eigen::Matrix<double, 12, 12> TimoshenkoElementStiffness(const BeamSection& s,
                                                                       double length_m);

}  // namespace ftstack::sim
