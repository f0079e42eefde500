// ftdiag: time to diagnose a 60 000-row × 6-channel simulator recording (issue 7 asks < 2 s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "bench/diag_jitter_data.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
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

// The low-pass filters alone on 10^6 rows × 8 columns of the clock benchmark's data: first order
// (τ = 1 s) and second order (10 Hz, ζ = 0.3), uniform against ±30 % jittered timestamps, so
// the cost of a jittered clock (per-row step coefficients) reads side by side with a uniform one.
const diag::DiagData& ClockData(bool jitter) {
  if (jitter) {
    static const diag::DiagData jittered = bench::MakeJitterData(1000000, true);
    return jittered;
  }
  static const diag::DiagData uniform = bench::MakeJitterData(1000000, false);
  return uniform;
}

void RunLowPass(benchmark::State& state, int order, bool jitter, double zeta) {
  const diag::DiagData& data = ClockData(jitter);
  const auto rows = static_cast<std::size_t>(data.rows());
  Eigen::MatrixXd out(data.real_mvv.rows(), data.real_mvv.cols());
  std::vector<const double*> in;
  std::vector<double*> o;
  for (Eigen::Index c = 0; c < data.real_mvv.cols(); ++c) {
    in.push_back(data.real_mvv.col(c).data());
    o.push_back(out.col(c).data());
  }
  for (auto _ : state) {
    if (order == 1) {
      diag::FirstOrderLowPassColumns(data.t_s.data(), rows, 1.0, in.data(), o.data(), in.size());
    } else {
      diag::SecondOrderLowPassColumns(data.t_s.data(), rows, 10.0, zeta, in.data(), o.data(),
                                      in.size());
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["rows"] = static_cast<double>(rows);
  state.SetLabel(jitter ? "jittered" : "uniform");
}

// BM_LowPassClock/<order>/<jitter>: order 1 or 2 (underdamped), jitter 0 (uniform) or 1 (±30 %).
void BM_LowPassClock(benchmark::State& state) {
  RunLowPass(state, static_cast<int>(state.range(0)), state.range(1) != 0, 0.3);
}
BENCHMARK(BM_LowPassClock)
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond);

// The same for an overdamped second order (ζ = 1.5; the diagnosis searches ζ up to 2).
void BM_LowPassClockOverdamped(benchmark::State& state) {
  RunLowPass(state, 2, state.range(0) != 0, 1.5);
}
BENCHMARK(BM_LowPassClockOverdamped)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
