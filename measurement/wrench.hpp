// The host wrench type: Fx Fy Fz (N) and Mx My Mz (N·m) in the sensor frame, with axis names and
// units.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>

namespace ftstack {

/// Number of wrench axes.
inline constexpr std::size_t kWrenchAxes = 6;

/// A wrench in the sensor frame, force first: Fx Fy Fz in N, then Mx My Mz in N·m.
using Wrench = Eigen::Matrix<double, 6, 1>;

/// Axis names in wrench order (also the recording's column names).
inline constexpr std::array<const char*, kWrenchAxes> kWrenchAxisNames = {"Fx", "Fy", "Fz",
                                                                          "Mx", "My", "Mz"};
/// Units of each axis, in wrench order.
inline constexpr std::array<const char*, kWrenchAxes> kWrenchAxisUnits = {"N",   "N",   "N",
                                                                          "N·m", "N·m", "N·m"};

/// True for the force axes (0–2), false for the moment axes (3–5).
[[nodiscard]] constexpr bool IsForceAxis(std::size_t axis) { return axis < 3; }

}  // namespace ftstack
