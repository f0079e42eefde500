// The fixed-point wrench type: order Fx Fy Fz Mx My Mz, sensor frame, and its integer units.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ftstack::fw {

/// Number of wrench components: Fx Fy Fz Mx My Mz (force first), sensor frame.
inline constexpr std::size_t kAxes = 6;

/// One output LSB of a force component: 1 mN.
inline constexpr double kForceLsbN = 1e-3;
/// One output LSB of a moment component: 10 µN·m = 0.01 N·mm.
inline constexpr double kMomentLsbNm = 1e-5;
/// Moment LSBs per mN·m (the Modbus int32 moment unit).
inline constexpr std::int32_t kMomentLsbPerMilliNm = 100;

/// Size of one LSB of axis `axis` in N (axes 0–2) or N·m (axes 3–5).
[[nodiscard]] constexpr double AxisLsb(std::size_t axis) {
  return axis < 3 ? kForceLsbN : kMomentLsbNm;
}

/// A wrench in output LSBs: Fx, Fy, Fz in mN; Mx, My, Mz in 10 µN·m.
using WrenchLsb = std::array<std::int32_t, kAxes>;

}  // namespace ftstack::fw
