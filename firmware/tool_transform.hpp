// Tool and mount transforms: move the wrench from the sensor origin to a tool or base point and
// frame, in fixed point.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"

namespace ftstack::fw {

/// Largest accepted |Dx|, |Dy|, |Dz|, m, and |Rx|, |Ry|, |Rz|, degrees.
inline constexpr double kMaxToolOffsetM = 10.0;
inline constexpr double kMaxToolAngleDeg = 360.0;

/// The tool frame as the Modbus holding registers 10–21 hold it: origin D (m) in the sensor frame
/// and orientation R = Rz(rz)·Ry(ry)·Rx(rx) (degrees; rotations about the fixed sensor axes x, then
/// y, then z). The columns of R are the tool axes expressed in the sensor frame.
struct ToolTransformParams {
  std::array<float, 3> d_m{};    ///< Dx, Dy, Dz, m
  std::array<float, 3> r_deg{};  ///< Rx, Ry, Rz, degrees
};

/// The same transform as an integer 6×6 matrix applied per sample:
///   F_tool = Rᵀ·F,   M_tool = Rᵀ·(M − D × F)
/// in output LSB (mN, 10 µN·m): row r gives y_r = round(Σ_j coef[r][j]·w_j / 2^shift[r]), 64-bit
/// accumulation; shift[r] is chosen so that no partial sum can leave ±2^62 for any int32 input.
struct FixedToolTransform {
  std::array<std::array<std::int64_t, kAxes>, kAxes> coef{};
  std::array<std::uint8_t, kAxes> shift{};
  bool identity = true;  ///< D = 0 and R = I: the transform is skipped
};

enum class TransformStatus : std::uint8_t {
  kOk = 0,
  kNotFinite,   ///< a NaN or infinity
  kOutOfRange,  ///< |D| > kMaxToolOffsetM or |R| > kMaxToolAngleDeg
};

/// Builds the fixed-point matrix (floating point, at configuration time only). On refusal *out is
/// left untouched.
[[nodiscard]] TransformStatus MakeToolTransform(const ToolTransformParams& params,
                                                FixedToolTransform* out);

/// The mount transform (holding registers 30–41): the sensor's pose in the base frame of the
/// machine it sits under — origin D_m (m) of the sensor frame in the base frame, orientation
/// R_m = Rz·Ry·Rx (rotations about the fixed base axes). It reports the wrench in the base frame,
/// about the base origin:  F_base = R_m·F,  M_base = R_m·M + D_m × (R_m·F).
/// With both set, the mount applies first and the tool transform is then read in the base frame
/// (its D and R give the tool frame in base coordinates): W_out = T_tool · T_mount · W_sensor.
/// A zero mount leaves the tool transform exactly as before (map version 1 behaviour).
[[nodiscard]] TransformStatus MakeMountedToolTransform(const ToolTransformParams& tool,
                                                       const ToolTransformParams& mount,
                                                       FixedToolTransform* out);

/// Applies a transform to one wrench (integer only). Sets *saturated if an axis was clamped to
/// int32.
void ApplyToolTransform(const FixedToolTransform& t, const WrenchLsb& in, WrenchLsb* out,
                        bool* saturated);

/// The tool-frame axes that depend on any sensor-frame axis in `sensor_invalid` (bit per axis):
/// row r is invalid when a non-zero coefficient takes an invalid axis into it.
[[nodiscard]] std::uint8_t ToolFrameInvalidAxes(const FixedToolTransform& t,
                                                std::uint8_t sensor_invalid);

}  // namespace ftstack::fw
