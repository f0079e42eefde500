// The simulated sensor and its converter: wrench source → sensor model → hal::sim::SimAdc.
#pragma once

#include <array>
#include <cstdint>

#include "hal/sim/sim_adc.hpp"
#include "sim/sensor_description.hpp"
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
  // The model is a pure function of (wrench, temperature): a held load (a constant wrench, a
  // replay between keyframes at equal values) reuses the last outputs instead of running the
  // physics again on every conversion.
  bool have_last_ = false;
  double last_temperature_c_ = 0.0;
  std::array<double, hal::kMaxChannels> last_mvv_{};
};

/// A sensor description read by its simulated converter: the one set-up of description →
/// simulated sensor → SimAdc that ftd's simulator, the rig simulation and the tests share. The
/// description and the source must outlive it.
class SimulatedAdc {
 public:
  SimulatedAdc(const SensorDescription& desc, const WrenchSource& source,
               const hal::sim::SimAdcParams& params)
      : desc_(desc), sensor_(*desc.model, source), adc_(sensor_, params) {}
  SimulatedAdc(const SimulatedAdc&) = delete;
  SimulatedAdc& operator=(const SimulatedAdc&) = delete;

  [[nodiscard]] hal::sim::SimAdc& adc() { return adc_; }
  [[nodiscard]] const SimulatedSensor& sensor() const { return sensor_; }
  /// The configuration that runs the description's converter (its channels, PGA gain) at rate_hz.
  [[nodiscard]] hal::AdcConfig Config(std::uint32_t rate_hz) const;

 private:
  const SensorDescription& desc_;
  SimulatedSensor sensor_;
  hal::sim::SimAdc adc_;
};

/// The converter parameters of `desc` at rate_hz as ftd runs them: AdcParamsAt, or, when the
/// converter cannot run that rate, the nominal operating point's noise with the rate left free.
[[nodiscard]] hal::sim::SimAdcParams AdcParamsOrNominal(const SensorDescription& desc,
                                                        std::uint32_t rate_hz);

}  // namespace ftstack::sim
