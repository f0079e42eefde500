// The built-in simulated sensor that `ftd --adc sim` runs: a wrist F/T sensor for a 3–7 kg arm.
#pragma once

#include <memory>

#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// Rated range of the built-in sensor: Fx, Fy ±200 N, Fz ±400 N, Mx, My ±10 N·m, Mz ±8 N·m.
[[nodiscard]] Wrench DefaultRated();

/// The built-in sensor, the physical model of sim/sensors/default.json: a three-beam aluminium
/// flexure (hub 10 mm, rim 35 mm, beams 4.5 × 6 mm) with six full bending bridges — at 0°, 120°,
/// 240° one out-of-plane bridge (Fz, Mx, My) and one in-plane bridge (Fx, Fy, Mz, its grids on the
/// side faces' mid-height line) per beam —,
/// 0.8 … 1.9 mV/V per term at rated load.
[[nodiscard]] std::unique_ptr<SensorModel> MakeDefaultSensor();

/// Channel noise of the built-in sensor's read-out, mV/V RMS: the ADS131M0x's 0.77 µV RMS at gain
/// 128 and 1 kSPS (datasheet noise table) over the 3.3 V excitation — about 1e-4 of rated range per
/// axis after decoupling.
inline constexpr double kDefaultNoiseMvv = 0.77e-3 / 3.3;

}  // namespace ftstack::sim
