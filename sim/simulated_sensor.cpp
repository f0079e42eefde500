#include "sim/simulated_sensor.hpp"

#include <stdexcept>

namespace ftstack::sim {

bool SimulatedSensor::Sample(double t_s, double* bridge_mvv, double* temperature_c) {
  Wrench w;
  double temp = 20.0;
  if (!source_.At(t_s, &w, &temp)) return false;
  const std::size_t n = channel_count();
  // Exact equality only: any change of load or temperature runs the model.
  if (!have_last_ || w != last_wrench_ || temp != last_temperature_c_) {
    model_.BridgeOutputsInto(w, temp, last_mvv_.data());  // no allocation: the sampling thread
    last_wrench_ = w;
    last_temperature_c_ = temp;
    have_last_ = true;
  }
  for (std::size_t i = 0; i < n; ++i) bridge_mvv[i] = last_mvv_[i];
  *temperature_c = temp;
  return true;
}

hal::AdcConfig SimulatedAdc::Config(std::uint32_t rate_hz) const {
  hal::AdcConfig cfg;
  cfg.channel_count = static_cast<std::uint8_t>(desc_.model->channel_count());
  cfg.gain = desc_.adc_gain;
  cfg.rate_hz = rate_hz;
  return cfg;
}

hal::sim::SimAdcParams AdcParamsOrNominal(const SensorDescription& desc, std::uint32_t rate_hz) {
  try {
    return AdcParamsAt(desc, rate_hz);
  } catch (const std::invalid_argument&) {
    hal::sim::SimAdcParams params = desc.adc;
    params.required_rate_hz = 0;
    return params;
  }
}

}  // namespace ftstack::sim
