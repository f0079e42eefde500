// Compliance of a beam's root in an elastic support, and a beam element with compliant ends.
#pragma once

#include <Eigen/Dense>
#include <array>

#include "sim/beam_element.hpp"

namespace ftstack::sim {

/// Compliance of the joint between an element end and what carries it, in the element's local
/// axes: ux uy uz in m/N, rx ry rz in rad/(N·m); each DOF on its own (no coupling). 0 = rigid.
using EndCompliance = std::array<double, 6>;

/// O'Donnell's coefficient (J. Appl. Mech. 27 (1960) 461): a strip of depth d and breadth b built
/// into a semi-infinite solid of the same breadth rotates at the root by
/// θ = kOdonnellRoot · M / (E · b · d²) under a root moment M (2-D, plane stress, measured).
inline constexpr double kOdonnellRoot = 16.67 / 3.14159265358979323846;

/// Root rotation compliance of a rectangular beam (width_m along local y, height_m along local z)
/// built into an elastic support of its own depth, per bending plane, from O'Donnell's strip:
/// rz (bending in the x–y plane, depth width_m) k/(E·h·w²), ry (x–z plane, depth height_m)
/// k/(E·w·h²). Torsion, axial and shear translation of the root are not included (0).
/// Throws std::invalid_argument on non-positive or non-finite input.
[[nodiscard]] EndCompliance BuiltInRootCompliance(double e_pa, double width_m, double height_m);

/// A 12-DOF element (local axes, end a at x = 0, end b at x = length_m) joined to its two
/// anchors through the end compliances ca and cb in series: the returned stiffness relates the
/// anchors' displacements to the forces on the anchors, which are the element's end forces
/// (zero-length joints carry no load of their own). Zero compliances return k_local.
[[nodiscard]] Eigen::Matrix<double, 12, 12> WithEndCompliance(
    const Eigen::Matrix<double, 12, 12>& k_local, double length_m, const EndCompliance& ca,
    const EndCompliance& cb);

}  // namespace ftstack::sim
