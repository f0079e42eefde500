// Fitting benchmark: 1 000 000 rig rows (simulated sensor → simulated ADC), affine model with
// block cross-validation and the λ grid, and the full automatic choice (affine + second order).
#include <benchmark/benchmark.h>

#include <cstdio>

#include "calibration/fit/fit.hpp"
#include "sim/rig.hpp"
#include "sim/sensor_description.hpp"

namespace {

using namespace ftstack;

const cal::RigData& Data() {
  static const cal::RigData data = [] {
    const sim::SensorDescription d = sim::DefaultSensorDescription();
    sim::RigDesignOptions ro;
    ro.hold_s = 5.0;
    ro.ramp_s = 1.0;
    const auto keys = sim::RigKeys(sim::DesignRig(d.model->rated(), ro), ro);
    // Rate chosen so the sequence gives at least 1e6 rows; then exactly 1e6 are kept.
    const double rate = 1e6 / keys.back().t_s * 1.001;
    Recording rec = sim::SimulateRig(d, keys, rate, 1);
    for (auto& c : rec.columns) c.resize(1000000);
    cal::BlockOptions bo;
    for (int a = 0; a < 6; ++a) bo.scale[static_cast<std::size_t>(a)] = d.model->rated()(a);
    return cal::RigDataFromRecording(rec, bo);
  }();
  return data;
}

void Fit(benchmark::State& state, std::vector<cal::ModelKind> models) {
  const cal::RigData& d = Data();
  cal::FitOptions fo;
  fo.models = std::move(models);
  double rms = 0;
  for (auto _ : state) {
    const cal::FitResult r = cal::FitCalibration(d, fo);
    rms = r.heldout_rms_si[2];
  }
  state.counters["rows"] = static_cast<double>(d.bridges.rows());
  state.counters["blocks"] = d.block_count;
  char label[64];
  std::snprintf(label, sizeof label, "heldout_fz_rms_n=%.4g", rms);
  state.SetLabel(label);
}

void BM_FitLinear1M(benchmark::State& state) { Fit(state, {cal::ModelKind::kLinear}); }
void BM_FitAuto1M(benchmark::State& state) { Fit(state, {}); }

BENCHMARK(BM_FitLinear1M)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_FitAuto1M)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
