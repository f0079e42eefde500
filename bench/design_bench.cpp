// Design explorer cost: one design of each family evaluated, and the whole panda-base sweep with
// refinement (what `ftsim design --require panda-base` does before writing its report).
#include <benchmark/benchmark.h>

#include "sim/design/explore.hpp"

namespace {

using namespace ftstack::sim::design;

void BM_EvaluateHubSpoke(benchmark::State& state) {
  const Readout r;
  for (auto _ : state) {
    const DesignModel m = HubSpoke(HubSpokeParams{}, r);
    benchmark::DoNotOptimize(Evaluate(m, DesignOptions{}).capacity.data());
  }
  state.counters["evaluations"] = 1;  // CSV output needs every counter in every run
}

void BM_EvaluateGuided(benchmark::State& state) {
  const Readout r;
  for (auto _ : state) {
    const DesignModel m = Guided(GuidedParams{}, r);
    benchmark::DoNotOptimize(Evaluate(m, DesignOptions{}).capacity.data());
  }
  state.counters["evaluations"] = 1;  // CSV output needs every counter in every run
}

void BM_SweepPandaBase(benchmark::State& state) {
  const Requirement req = LoadRequirement("panda-base");
  const SweepOptions o;
  std::size_t n = 0;
  for (auto _ : state) {
    std::vector<Candidate> cs = Sweep(o, &req, nullptr);
    n = cs.size() + static_cast<std::size_t>(RefineGuided(&cs, req, o, 6));
    benchmark::DoNotOptimize(cs.data());
  }
  state.counters["evaluations"] = static_cast<double>(n);
}

}  // namespace

BENCHMARK(BM_EvaluateHubSpoke)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EvaluateGuided)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SweepPandaBase)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_MAIN();
