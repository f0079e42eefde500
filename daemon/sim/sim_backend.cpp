#include "daemon/sim/sim_backend.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "hal/sim/sim_adc.hpp"
#include "measurement/recording.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/load_profile.hpp"
#include "sim/piecewise_compose.hpp"
#include "sim/record.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/streamed_bridges.hpp"
#include "sim/wrench_source.hpp"

namespace ftstack::daemon {
namespace {

/// Wake-ups per second of the sampling thread at most: the simulated converter delivers
/// rate / kBlockHz samples per data-ready (1 ms of latency for the block's first sample).
constexpr std::uint32_t kBlockHz = 1000;

/// Bridge outputs rendered once at start-up by the simulator's effect composition (what
/// `ftsim record --effect` injects), read back at each conversion's time; after the rendered span
/// the last sample holds.
class RenderedBridges final : public hal::sim::BridgeSignalSource {
 public:
  RenderedBridges(Eigen::MatrixXd mvv, std::vector<double> temp_c, double rate_hz)
      : mvv_(std::move(mvv)), temp_c_(std::move(temp_c)), rate_hz_(rate_hz) {}
  [[nodiscard]] std::uint8_t channel_count() const override {
    return static_cast<std::uint8_t>(mvv_.rows());
  }
  [[nodiscard]] bool Sample(double t_s, double* bridge_mvv, double* temperature_c) override {
    const double at = std::floor(t_s * rate_hz_ + 0.5);
    const Eigen::Index last = mvv_.cols() - 1;
    const Eigen::Index i =
        at <= 0 ? 0 : (at >= static_cast<double>(last) ? last : static_cast<Eigen::Index>(at));
    for (Eigen::Index c = 0; c < mvv_.rows(); ++c) bridge_mvv[c] = mvv_(c, i);
    if (temperature_c != nullptr) *temperature_c = temp_c_[static_cast<std::size_t>(i)];
    return true;
  }

 private:
  Eigen::MatrixXd mvv_;
  std::vector<double> temp_c_;
  double rate_hz_;
};

/// Recordings up to this many rows are composed whole at start-up (exactly what `ftsim record`
/// composes); longer ones piece by piece while they are read (bounded memory: a 24 h profile at
/// 1 kHz would take ≈ 4 GB whole).
constexpr double kWholeRows = 2e6;
/// Rows per piece of a streamed recording (65 s at 1 kHz).
constexpr std::size_t kPieceRows = std::size_t{1} << 16;

/// The bridges of `desc` under the options' profile (or constant wrench) with --sim-effect
/// injected, over --sim-span-s at the sample rate. Throws on a bad effect or profile.
std::unique_ptr<hal::sim::BridgeSignalSource> Render(const sim::SensorDescription& desc,
                                                     const FtdOptions& opt) {
  const sim::SensorModel& model = *desc.model;
  sim::LoadProfile profile;
  if (!opt.sim_profile.empty()) {
    profile = sim::MakeProfile(opt.sim_profile, model.rated(), opt.seed, opt.sim_span_s);
  } else {
    Wrench w = Wrench::Zero();
    if (opt.sim_wrench) {
      for (int i = 0; i < 6; ++i) w(i) = (*opt.sim_wrench)[static_cast<std::size_t>(i)];
    }
    profile = sim::LoadProfile("constant", {0.0}, {w}, {0.0}, {20.0}, opt.sim_span_s, opt.rate_hz);
  }
  const double rows = profile.duration_s() * opt.rate_hz;
  if (!(rows >= 2)) {
    throw std::invalid_argument("--sim-span-s: " + std::to_string(rows) +
                                " samples to render (at least 2: lengthen the span)");
  }
  if (rows > kWholeRows) {
    std::vector<sim::Effect> effects = sim::ResolveEffects(
        model, profile, opt.rate_hz, sim::ParseEffects(opt.sim_effects), opt.seed);
    return std::make_unique<sim::StreamedBridges>(
        std::make_unique<sim::PiecewiseComposition>(model, std::move(profile), opt.rate_hz,
                                                    std::move(effects), kPieceRows),
        opt.rate_hz);
  }
  sim::ComposeSetup setup =
      sim::SetUpCompose(model, profile, opt.rate_hz, sim::ParseEffects(opt.sim_effects), opt.seed);
  Eigen::MatrixXd mvv = sim::ComposeWithEffects(&setup);
  return std::make_unique<RenderedBridges>(std::move(mvv), setup.in.temp_c, opt.rate_hz);
}

class SimulatedBackend final : public AdcBackend {
 public:
  explicit SimulatedBackend(const FtdOptions& opt) : desc_(sim::DefaultSensorDescription()) {
    if (!opt.sim_effects.empty() || !opt.sim_profile.empty()) {
      rendered_ = Render(desc_, opt);
      hal::sim::SimAdcParams params = AdcParams(opt);
      rendered_adc_ = std::make_unique<hal::sim::SimAdc>(*rendered_, params);
      return;
    }
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
    simulated_ = std::make_unique<sim::SimulatedAdc>(desc_, *source_, AdcParams(opt));
  }
  hal::Adc& adc() override {
    return rendered_adc_ ? static_cast<hal::Adc&>(*rendered_adc_) : simulated_->adc();
  }
  [[nodiscard]] std::uint8_t channel_count() const override {
    return static_cast<std::uint8_t>(desc_.model->channel_count());
  }
  [[nodiscard]] std::uint16_t gain() const override { return desc_.adc_gain; }
  [[nodiscard]] std::optional<cal::CalFile> BuiltinCalibration(
      const hal::AdcInfo& adc) const override {
    return sim::IdealCalibration(*desc_.model, adc);
  }

 private:
  /// The built-in sensor's converter at the requested rate (its datasheet noise); a rate the
  /// converter cannot run keeps the nominal operating point's noise.
  [[nodiscard]] hal::sim::SimAdcParams AdcParams(const FtdOptions& opt) const {
    hal::sim::SimAdcParams params = sim::AdcParamsOrNominal(desc_, opt.rate_hz);
    params.seed = opt.seed;
    params.realtime = opt.paced;
    params.speed = opt.sim_speed;
    params.temperature = opt.sim_temperature;
    params.stall_every = opt.sim_stall_every;
    params.stall_us = static_cast<std::uint32_t>(opt.sim_stall_ms * 1000.0);
    // One wake-up of the sampling thread per millisecond of samples at most (a converter FIFO's
    // watermark): the samples keep their own conversion times, the wake-ups cost the kernel.
    params.block_samples = static_cast<std::uint16_t>(
        std::clamp<std::uint32_t>(opt.rate_hz / kBlockHz, 1, hal::sim::kMaxBlockSamples));
    return params;
  }

  sim::SensorDescription desc_;
  std::unique_ptr<hal::sim::BridgeSignalSource> rendered_;
  std::unique_ptr<hal::sim::SimAdc> rendered_adc_;
  std::unique_ptr<sim::WrenchSource> source_;
  std::unique_ptr<sim::SimulatedAdc> simulated_;
};

}  // namespace

std::unique_ptr<AdcBackend> MakeSimulatedBackend(const FtdOptions& options) {
  return std::make_unique<SimulatedBackend>(options);
}

}  // namespace ftstack::daemon
