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
  const hal::sim::SimAdcParams params = sim::AdcParamsOrNominal(desc, rate_hz);
  sim::ConstantWrench zero(Wrench::Zero());
  sim::SimulatedAdc simulated(desc, zero, params);
  hal::sim::SimAdc& adc = simulated.adc();
  if (adc.Configure(simulated.Config(rate_hz)) != hal::Status::kOk) {
    throw std::runtime_error("built-in ADC refused");
  }
  return BuiltinAdc{adc.Info(), params.noise_rms_mvv};
}

}  // namespace ftstack::test
