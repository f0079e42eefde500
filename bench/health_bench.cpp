// The health watch's cost per sample (firmware/health_watch): a realistic load at 1 and 8 kHz —
// noise, a load step with ringing every 2 s (so transient captures, holds and zero spells all
// run) — and the worst single sample, one ringing analysis after a transient capture.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "firmware/health_watch.hpp"

namespace {

using ftstack::fw::HealthInput;
using ftstack::fw::HealthWatch;
using ftstack::fw::WrenchLsb;

constexpr WrenchLsb kRated = {200000, 200000, 400000, 1000000, 1000000, 800000};

/// 4 s of input at `rate`: ± noise, Fz stepping to 40 % of rated at 1 s and back at 3 s, each
/// step ringing at 25 Hz (ζ = 0.04, 1 % of the step).
std::vector<HealthInput> Inputs(std::uint32_t rate) {
  std::vector<HealthInput> v(4 * rate);
  std::uint64_t s = 88172645463325252ull;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double t = static_cast<double>(i) / rate;
    const double on = t >= 1.0 && t < 3.0 ? 1.0 : 0.0;
    const double since = t >= 3.0 ? t - 3.0 : (t >= 1.0 ? t - 1.0 : 10.0);
    const double wn = 2 * M_PI * 25.0;
    const double ring =
        0.01 * std::exp(-0.04 * wn * since) * std::cos(wn * since) * (t >= 3.0 ? -1.0 : 1.0);
    HealthInput& in = v[i];
    in.valid = true;
    in.has_temperature = true;
    in.temperature_mdegc = 21000;
    for (std::size_t r = 0; r < 6; ++r) {
      s ^= s << 13;
      s ^= s >> 7;
      s ^= s << 17;
      in.tared[r] = static_cast<std::int32_t>((s >> 40) % 41) - 20;
    }
    in.tared[2] += static_cast<std::int32_t>(std::lround((on + ring) * 0.4 * kRated[2]));
    in.untared = in.tared;  // the rainflow counters run too
    in.untared_valid = true;
  }
  return v;
}

void BM_HealthWatchStep(benchmark::State& state) {
  const auto rate = static_cast<std::uint32_t>(state.range(0));
  const std::vector<HealthInput> in = Inputs(rate);
  static HealthWatch watch;  // 12 KB of capture: not on the benchmark's stack
  if (!watch.Configure(rate, kRated)) state.SkipWithError("Configure");
  std::size_t i = 0;
  for (auto _ : state) {
    watch.Step(in[i]);
    benchmark::DoNotOptimize(watch.report().findings);
    if (++i == in.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_HealthWatchStep)->Arg(1000)->Arg(8000);

/// The worst sample: one MeasureRinging over a 512-sample capture (each of the six samples after a
/// capture ends analyses one axis).
void BM_RingingAnalysis(benchmark::State& state) {
  std::vector<std::int32_t> x(HealthWatch::kRingCapture);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = i / 1000.0;
    x[i] = static_cast<std::int32_t>(160000 + 1600 * std::exp(-6.3 * t) * std::cos(157 * t));
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(ftstack::fw::MeasureRinging(x.data(), x.size(), 1000, 40));
  }
}
BENCHMARK(BM_RingingAnalysis);

}  // namespace

BENCHMARK_MAIN();
