// Test helper: the converter that `ftd --adc sim` reads the built-in sensor with (scaling, noise).
#pragma once

#include <stdexcept>

#include "hal/sim/sim_adc.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/wrench_source.hpp"

namespace ftstack::test {

/// Scaling and input-referred noise of the built-in sensor's ADC at `rate_hz`, found the way ftd
/// finds them: the sensor description's converter, configured.
struct BuiltinAdc {
  hal::AdcInfo info;
  double noise_rms_mvv = 0;
};

inline BuiltinAdc BuiltinSimAdc(std::uint32_t rate_hz = 1000) {
  const sim::SensorDescription desc = sim::DefaultSensorDescription();
  hal::sim::SimAdcParams params;
  try {
    params = sim::AdcParamsAt(desc, rate_hz);
  } catch (const std::invalid_argument&) {
    params = desc.adc;
    params.required_rate_hz = 0;
  }
  sim::ConstantWrench zero(Wrench::Zero());
  sim::SimulatedSensor sensor(*desc.model, zero);
  hal::sim::SimAdc adc(sensor, params);
  hal::AdcConfig cfg;
  cfg.channel_count = static_cast<std::uint8_t>(desc.model->channel_count());
  cfg.gain = desc.adc_gain;
  cfg.rate_hz = rate_hz;
  if (adc.Configure(cfg) != hal::Status::kOk) throw std::runtime_error("built-in ADC refused");
  return BuiltinAdc{adc.Info(), params.noise_rms_mvv};
}

}  // namespace ftstack::test
