// The simulated sensor seen by the simulated ADC: a wrench source driving a sensor model.
#pragma once

#include "hal/sim/sim_adc.hpp"
#include "sim/sensor_model.hpp"
#include "sim/wrench_source.hpp"

namespace ftstack::sim {

/// Connects physics to the HAL: at time t the source's wrench goes through the model and comes
/// out as bridge outputs in mV/V for hal::sim::SimAdc to convert into counts.
class SimulatedSensor final : public hal::sim::BridgeSignalSource {
 public:
  SimulatedSensor(const SensorModel& model, const WrenchSource& source)
      : model_(model), source_(source) {}
  [[nodiscard]] std::uint8_t channel_count() const override {
    return static_cast<std::uint8_t>(model_.channel_count());
  }
  [[nodiscard]] bool Sample(double t_s, double* bridge_mvv, double* temperature_c) override;
  /// The wrench applied at the last Sample call (N, N·m).
  [[nodiscard]] const Wrench& last_wrench() const { return last_wrench_; }

 private:
  const SensorModel& model_;
  const WrenchSource& source_;
  Wrench last_wrench_ = Wrench::Zero();
};

}  // namespace ftstack::sim
