// Double-precision evaluation of a calibration (the reference the fixed-point core is held to).
#pragma once

#include <array>

#include "firmware/fixed_calibration.hpp"

namespace ftstack::cal {

/// Wrench (N, N·m) that `cal` gives for bridge outputs `bridge_mvv` (channel_count values, input
/// unit) at body temperature `temperature_c` (°C; clamped to the compensated range; ignored when
/// the calibration has no temperature compensation). Evaluates the documented formula of
/// fw::FloatCalibration in double precision, independently of the integer path.
[[nodiscard]] std::array<double, 6> EvaluateCalibration(const fw::FloatCalibration& cal,
                                                        const double* bridge_mvv,
                                                        double temperature_c);

/// True when the calibration uses second-order terms or temperature compensation.
[[nodiscard]] inline bool HasExtendedTerms(const fw::FloatCalibration& cal) {
  return cal.product_count > 0 || cal.temperature_compensated;
}

}  // namespace ftstack::cal
