// The health watch's cost per sample (firmware/health_watch): a realistic load at 1 and 8 kHz —
// noise, a load step with ringing every 2 s (so transient captures, holds and zero spells all
// run) — and the worst single sample, one ringing analysis after a transient capture.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "bench/health_inputs.hpp"
#include "firmware/health_watch.hpp"

namespace {

using ftstack::bench::HealthInputs;
using ftstack::bench::kHealthRated;
using ftstack::fw::HealthInput;
using ftstack::fw::HealthWatch;

void BM_HealthWatchStep(benchmark::State& state) {
  const auto rate = static_cast<std::uint32_t>(state.range(0));
  const std::vector<HealthInput> in = HealthInputs(rate);
  static HealthWatch watch;  // 12 KB of capture: not on the benchmark's stack
  if (!watch.Configure(rate, kHealthRated)) state.SkipWithError("Configure");
  std::size_t i = 0;
  for (auto _ : state) {
    watch.Step(in[i]);
    benchmark::DoNotOptimize(watch.report().findings);
    if (++i == in.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_HealthWatchStep)->Arg(1000)->Arg(8000);

/// A whole ringing analysis of one axis (a 512-sample capture), as the watch spreads it over
/// four samples.
void BM_RingingAnalysis(benchmark::State& state) {
  const std::vector<std::int32_t> x = ftstack::bench::RingingCapture();
  for (auto _ : state) {
    benchmark::DoNotOptimize(ftstack::fw::MeasureRinging(x.data(), x.size(), 1000, 40));
  }
}
BENCHMARK(BM_RingingAnalysis);

/// The worst sample's extra work, bounded from above: the level's slice and the first crossing
/// slice of an analysis together (the watch does them on two samples).
void BM_RingingWorstSlice(benchmark::State& state) {
  const std::vector<std::int32_t> x = ftstack::bench::RingingCapture();
  ftstack::fw::RingingScan scan;
  for (auto _ : state) {
    scan.Start(x.data(), x.size(), 1000, 40);
    benchmark::DoNotOptimize(scan.Advance(HealthWatch::kRingSlice));
    benchmark::DoNotOptimize(scan.Advance(HealthWatch::kRingSlice));
  }
}
BENCHMARK(BM_RingingWorstSlice);

}  // namespace

BENCHMARK_MAIN();
