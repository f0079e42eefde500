// The ideal calibration of a simulated sensor: the pseudo-inverse of its small-signal sensitivity.
#pragma once

#include "calibration/file/cal_file.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// The calibration a perfect rig would find for `model` read by `adc`: matrix = pinv(S) at zero
/// load and 20 °C, zero offsets = the model's unloaded outputs.
[[nodiscard]] cal::CalFile IdealCalibration(const SensorModel& model, const hal::AdcInfo& adc);

}  // namespace ftstack::sim
