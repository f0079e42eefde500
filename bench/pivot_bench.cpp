// Time of one crossed-strip pivot solve, exact elastica vs Wittrick, with Newton iteration counts.
#include <benchmark/benchmark.h>

#include <numbers>

#include "sim/pivot/pivot.hpp"

namespace {

using ftstack::sim::pivot::PivotGeometry;
using ftstack::sim::pivot::PivotLoad;
using ftstack::sim::pivot::PivotMethod;

// Cases on the seed report's strip (alpha 45°): args = theta (deg), V (N), H (N).
void Cases(benchmark::internal::Benchmark* b) {
  b->Args({5, 0, 0})->Args({20, 10, 5})->Args({20, -60, 20})->Args({30, 100, 100});
}

void Solve(benchmark::State& state, PivotMethod method) {
  const PivotGeometry g;
  const PivotLoad load{static_cast<double>(state.range(0)) * std::numbers::pi / 180.0,
                       static_cast<double>(state.range(1)), static_cast<double>(state.range(2))};
  int iterations = 0;
  bool valid = false;
  for (auto _ : state) {
    const auto r = ftstack::sim::pivot::SolvePivot(g, load, method);
    benchmark::DoNotOptimize(r.c_nm);
    iterations = r.iterations;
    valid = r.valid;
  }
  state.counters["newton_iterations"] = iterations;
  state.counters["valid"] = valid ? 1 : 0;
}

void BM_PivotExact(benchmark::State& state) { Solve(state, PivotMethod::kExact); }
void BM_PivotWittrick(benchmark::State& state) { Solve(state, PivotMethod::kWittrick); }

BENCHMARK(BM_PivotExact)->Apply(Cases)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PivotWittrick)->Apply(Cases)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
