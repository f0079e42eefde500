// Physics simulator timings: one full-chain sample (wrench → strains → bridges → ADC counts), the
// bridge model alone, and building the model (JSON → flexure solve), beside the linear model.
#include <benchmark/benchmark.h>

#include <array>

#include "hal/sim/sim_adc.hpp"
#include "sim/default_sensor.hpp"
#include "sim/flexure_body.hpp"
#include "sim/physical_sensor.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/wrench_source.hpp"

namespace {

using namespace ftstack;

Wrench Load() {
  Wrench w;
  w << 40, -25, 150, 2.5, -1.2, 0.8;
  return w;
}

void BM_BuildModel(benchmark::State& state) {
  for (auto _ : state) {
    auto m = sim::ParsePhysicalSensor(sim::DefaultSensorJson(), "builtin");
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_BuildModel);

void BM_BuildFlexureBody(benchmark::State& state) {
  const auto m = sim::ParsePhysicalSensor(sim::DefaultSensorJson(), "builtin");
  const sim::FlexureGeometry g = m->body().geometry();
  for (auto _ : state) {
    sim::FlexureBody body(g);
    benchmark::DoNotOptimize(body.Stiffness());
  }
}
BENCHMARK(BM_BuildFlexureBody);

void BM_BridgeOutputs(benchmark::State& state) {
  const auto m = sim::ParsePhysicalSensor(sim::DefaultSensorJson(), "builtin");
  std::array<double, 8> out{};
  Wrench w = Load();
  for (auto _ : state) {
    m->BridgeOutputsInto(w, 23.0, out.data());
    benchmark::DoNotOptimize(out);
    w(2) += 1e-9;
  }
}
BENCHMARK(BM_BridgeOutputs);

// One sample through SimulatedSensor (wrench → model → mV/V) and SimAdc (noise, quantisation,
// clipping → counts): arg 0 = physical model, arg 1 = linear model with the same sensitivity.
void BM_FullChainSample(benchmark::State& state) {
  const sim::SensorDescription d = sim::DefaultSensorDescription();
  const sim::LinearSensorModel linear(d.model->Sensitivity(), d.model->rated(), "linear");
  const sim::SensorModel& model = state.range(0) == 0 ? *d.model : linear;
  sim::ConstantWrench source(Load(), 23.0);
  sim::SimulatedSensor sensor(model, source);
  hal::sim::SimAdc adc(sensor, d.adc);
  hal::AdcConfig cfg;
  cfg.channel_count = static_cast<std::uint8_t>(model.channel_count());
  cfg.gain = d.adc_gain;
  cfg.rate_hz = static_cast<std::uint32_t>(d.rate_hz);
  if (adc.Configure(cfg) != hal::Status::kOk) state.SkipWithError("configure failed");
  hal::AdcSample s;
  for (auto _ : state) {
    (void)adc.WaitDataReady(0);
    (void)adc.Read(s);
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_FullChainSample)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
