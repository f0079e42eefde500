// Cost of making a simulated recording in-process (sim::MakeRecording), per row, with and without
// effects.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "sim/record.hpp"

namespace {

void Run(benchmark::State& state, const std::vector<std::string>& effects) {
  ftstack::sim::RecordRequest req;
  req.profile = "rig";
  req.duration_s = static_cast<double>(state.range(0));
  req.effects = ftstack::sim::ParseEffects(effects);
  std::size_t rows = 0;
  for (auto _ : state) {
    const auto res = ftstack::sim::MakeRecording(req);
    rows = res.real.rows();
    benchmark::DoNotOptimize(res.real.columns.data());
  }
  state.counters["rows"] = static_cast<double>(rows);
}

// Builtin sensor, rig profile at 200 Hz: no effect; one effect (its truth footprint costs one
// more model pass); three effects.
void BM_RecordNone(benchmark::State& s) { Run(s, {}); }
void BM_RecordCreep(benchmark::State& s) { Run(s, {"creep"}); }
void BM_RecordThree(benchmark::State& s) { Run(s, {"creep", "hysteresis", "mains_interference"}); }

BENCHMARK(BM_RecordNone)->Arg(60)->Arg(300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecordCreep)->Arg(60)->Arg(300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecordThree)->Arg(60)->Arg(300)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
