// The built-in simulated sensor that `ftd --adc sim` runs: a wrist F/T sensor for a 3–7 kg arm.
#pragma once

#include <memory>

#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// Rated range of the built-in sensor: Fx, Fy ±200 N, Fz ±400 N, Mx, My ±10 N·m, Mz ±8 N·m.
[[nodiscard]] Wrench DefaultRated();

/// The built-in sensor: six bridges on a three-beam body (bending bridges at 0°, 120°, 240°
/// sensing Fz, Mx, My; shear bridges at 60°, 180°, 300° sensing Fx, Fy, Mz), about 0.6 mV/V per
/// term at rated load.
[[nodiscard]] std::unique_ptr<SensorModel> MakeDefaultSensor();

/// Channel noise of 24-bit read-out of the built-in sensor, mV/V RMS (≈ 1e-4 of rated output).
inline constexpr double kDefaultNoiseMvv = 1.0e-4;

}  // namespace ftstack::sim
