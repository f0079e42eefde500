#include "daemon/sim_backend.hpp"

#include <stdexcept>

#include "hal/sim/sim_adc.hpp"
#include "measurement/recording.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/wrench_source.hpp"

namespace ftstack::daemon {
namespace {

class SimulatedBackend final : public AdcBackend {
 public:
  explicit SimulatedBackend(const FtdOptions& opt) : desc_(sim::DefaultSensorDescription()) {
    if (!opt.replay.empty()) {
      ReadOptions ro;
      ro.required = {"t"};
      ro.require_wrench = true;
      source_ = sim::ReplayWrench(ReadRecording(opt.replay, ro));
    } else {
      Wrench w = Wrench::Zero();
      if (opt.sim_wrench) {
        for (int i = 0; i < 6; ++i) w(i) = (*opt.sim_wrench)[static_cast<std::size_t>(i)];
      }
      source_ = std::make_unique<sim::ConstantWrench>(w);
    }
    // The built-in sensor's converter at the requested rate (its datasheet noise); a rate the
    // converter cannot run keeps the nominal operating point's noise.
    hal::sim::SimAdcParams params = sim::AdcParamsOrNominal(desc_, opt.rate_hz);
    params.seed = opt.seed;
    params.realtime = opt.paced;
    params.stall_every = opt.sim_stall_every;
    params.stall_us = static_cast<std::uint32_t>(opt.sim_stall_ms * 1000.0);
    simulated_ = std::make_unique<sim::SimulatedAdc>(desc_, *source_, params);
  }
  hal::Adc& adc() override { return simulated_->adc(); }
  [[nodiscard]] std::uint8_t channel_count() const override {
    return static_cast<std::uint8_t>(desc_.model->channel_count());
  }
  [[nodiscard]] std::uint16_t gain() const override { return desc_.adc_gain; }
  [[nodiscard]] std::optional<cal::CalFile> BuiltinCalibration(
      const hal::AdcInfo& adc) const override {
    return sim::IdealCalibration(*desc_.model, adc);
  }

 private:
  sim::SensorDescription desc_;
  std::unique_ptr<sim::WrenchSource> source_;
  std::unique_ptr<sim::SimulatedAdc> simulated_;
};

}  // namespace

std::unique_ptr<AdcBackend> MakeSimulatedBackend(const FtdOptions& options) {
  return std::make_unique<SimulatedBackend>(options);
}

}  // namespace ftstack::daemon
