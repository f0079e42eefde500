// ftdiag: time to diagnose a 60 000-row × 6-channel simulator recording (issue 7 asks < 2 s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "bench/diag_jitter_data.hpp"
#include "diagnosis/diagnose.hpp"
#include "sim/record.hpp"

namespace {

using namespace ftstack;

diag::DiagData MakeData(const std::string& effect, double duration_s) {
  sim::RecordRequest req;
  req.profile = "rig";
  req.seed = 3;
  req.duration_s = duration_s;
  if (!effect.empty()) req.effects = sim::ParseEffects({effect});
  const auto rec = sim::MakeRecording(req);
  return diag::FromRecordings(rec.sim, rec.real);
}

// 300 s at 200 Hz = 60 000 rows; a concealed creep (needs a τ search, pairs are tried).
void BM_Diagnose60k(benchmark::State& state) {
  static const diag::DiagData data = MakeData("creep", 300.0);
  for (auto _ : state) {
    auto r = diag::Diagnose(data);
    benchmark::DoNotOptimize(r.hold_rms_after);
  }
  state.counters["rows"] = static_cast<double>(data.rows());
  state.counters["channels"] = data.channels();
}
// The diagnosis runs fits on threads: CPU time of the whole process, and wall time.
BENCHMARK(BM_Diagnose60k)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Noise only (no claim: the pair stage is skipped) for comparison in the same run.
void BM_Diagnose60kNone(benchmark::State& state) {
  static const diag::DiagData data = MakeData("", 300.0);
  for (auto _ : state) {
    auto r = diag::Diagnose(data);
    benchmark::DoNotOptimize(r.hold_rms_after);
  }
  state.counters["rows"] = static_cast<double>(data.rows());
}
BENCHMARK(BM_Diagnose60kNone)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Uniform against ±30 % jittered timestamps, same size, same run (issue 12: ≤ 3 s for 10^5
// rows × 8 channels, ≤ 20 s for 10^6).
void BM_DiagnoseClock(benchmark::State& state) {
  const auto rows = static_cast<int>(state.range(0));
  const bool jitter = state.range(1) != 0;
  const diag::DiagData data = bench::MakeJitterData(rows, jitter);
  for (auto _ : state) {
    auto r = diag::Diagnose(data);
    benchmark::DoNotOptimize(r.hold_rms_after);
  }
  state.counters["rows"] = rows;
  state.SetLabel(jitter ? "jittered" : "uniform");
}
BENCHMARK(BM_DiagnoseClock)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_DiagnoseClock)
    ->Args({1000000, 0})
    ->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Name("BM_DiagnoseClock1M");

}  // namespace

BENCHMARK_MAIN();
