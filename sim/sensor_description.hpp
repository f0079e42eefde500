// Sensor description files (JSON): which sensor model, its ADC and rated ranges, for
// ftsim/ftdiag/ftd.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "hal/sim/sim_adc.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// A sensor description that cannot be used; what() names the file (line:column for syntax).
class SensorDescriptionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A sensor ready to simulate: the model (load/temperature → mV/V) and its read-out.
struct SensorDescription {
  std::string name;
  std::shared_ptr<const SensorModel> model;
  hal::sim::SimAdcParams adc;    ///< converter (noise in mV/V RMS, resolution, reference ratio)
  std::uint16_t adc_gain = 128;  ///< PGA gain
  double rate_hz = 1000.0;       ///< sample rate, Hz
};

/// The built-in sensor that `ftd --adc sim` runs (sim::MakeDefaultSensor with its 24-bit ADC).
[[nodiscard]] SensorDescription DefaultSensorDescription();

/// Reads a sensor description. "builtin" (or an empty path) gives DefaultSensorDescription().
/// Schema "ftstack-sensor/1": {"schema", "name", "model": {"type": "linear", "sensitivity_mvv":
/// [[6 numbers] × N], "rated": [6], "zero_mvv": [N]}, "adc": {"noise_mvv", "bits", "gain",
/// "reference_ratio", "rate_hz"}}. Other model types are added by the physics simulator.
[[nodiscard]] SensorDescription LoadSensorDescription(const std::string& path);

}  // namespace ftstack::sim
