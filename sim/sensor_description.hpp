// Sensor description files (JSON): which sensor model, its ADC and rated ranges, for
// ftsim/ftdiag/ftd.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "hal/sim/sim_adc.hpp"
#include "sim/adc_models.hpp"
#include "sim/physical_sensor.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// A sensor description that cannot be used; what() is one line naming file:line:column.
class SensorDescriptionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A sensor ready to simulate: the model (load/temperature → mV/V) and its read-out.
struct SensorDescription {
  std::string name;
  std::shared_ptr<const SensorModel> model;
  AdcSpec adc_spec;  ///< the converter model (chip, gain, rate, excitation)
  /// Its operating point at rate_hz: noise (mV/V RMS), span, required gain. The rate is left free
  /// (required_rate_hz = 0) so callers may run other rates; AdcParamsAt gives their exact noise.
  hal::sim::SimAdcParams adc;
  std::uint16_t adc_gain = 128;  ///< PGA gain
  double rate_hz = 1000.0;       ///< sample rate, Hz
};

/// The built-in sensor that `ftd --adc sim` runs: sim/sensors/default.json (compiled in), a
/// three-beam aluminium flexure with six full bridges read by an ADS131M06 at 1 kSPS.
[[nodiscard]] SensorDescription DefaultSensorDescription();

/// The text of sim/sensors/default.json as compiled into the program.
[[nodiscard]] const std::string& DefaultSensorJson();

/// Reads a sensor description. "builtin" (or an empty path) gives DefaultSensorDescription().
/// Schema "ftstack-sensor/1" (docs/physics.md lists every key):
///   {"schema", "name", "model": {"type": "linear", "sensitivity_mvv": [[6] × N], "rated": [6],
///    "zero_mvv": [N]} | {"type": "flexure", "rated", "material", "body", "gauge", "electrical",
///    "bridges", "max_condition_number"},
///    "adc": {"type": "generic", "noise_mvv", "bits", "gain", "reference_ratio", "rate_hz"} |
///           {"type": "hx711" | "ads131m0x", "gain", "rate_hz", "excitation_v", "reference_v",
///            "global_chop"}}
/// Throws SensorDescriptionError with file:line:column on any problem.
[[nodiscard]] SensorDescription LoadSensorDescription(const std::string& path);

/// Parses description text; `origin` names it in errors (a path).
[[nodiscard]] SensorDescription ParseSensorDescription(const std::string& text,
                                                       const std::string& origin);

/// The physical model of a "flexure" description (throws SensorDescriptionError otherwise).
[[nodiscard]] std::unique_ptr<PhysicalSensorModel> ParsePhysicalSensor(const std::string& text,
                                                                       const std::string& origin);

/// The ADC parameters of `d`'s converter at another data rate (same chip, gain, excitation).
/// Throws std::invalid_argument when the converter cannot run at that rate.
[[nodiscard]] hal::sim::SimAdcParams AdcParamsAt(const SensorDescription& d, std::uint32_t rate_hz);

}  // namespace ftstack::sim
