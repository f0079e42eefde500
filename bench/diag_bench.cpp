// ftdiag: time to diagnose a 60 000-row × 6-channel simulator recording (issue 7 asks < 2 s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

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
BENCHMARK(BM_Diagnose60k)->Unit(benchmark::kMillisecond)->Iterations(3);

// Noise only (no claim: the pair stage is skipped) for comparison in the same run.
void BM_Diagnose60kNone(benchmark::State& state) {
  static const diag::DiagData data = MakeData("", 300.0);
  for (auto _ : state) {
    auto r = diag::Diagnose(data);
    benchmark::DoNotOptimize(r.hold_rms_after);
  }
  state.counters["rows"] = static_cast<double>(data.rows());
}
BENCHMARK(BM_Diagnose60kNone)->Unit(benchmark::kMillisecond)->Iterations(3);

/// 8 bridges, `rows` rows at a nominal 150 Hz, timestamps uniform or jittered by ±30 % of the
/// period (uniform random); a staircase of random loads seen through a fixed 8 × 6 sensitivity,
/// the real side adds a first-order creep (τ = 20 s, integrated with the actual dt) and noise.
diag::DiagData MakeJitterData(int rows, bool jitter) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  diag::DiagData d;
  d.sim_name = "bench";
  d.real_name = jitter ? "jittered" : "uniform";
  d.t_s.resize(static_cast<std::size_t>(rows));
  d.wrench.resize(rows, 6);
  d.sim_mvv.resize(rows, 8);
  d.real_mvv.resize(rows, 8);
  Eigen::MatrixXd s(8, 6);
  for (int c = 0; c < 8; ++c) {
    for (int a = 0; a < 6; ++a) s(c, a) = 0.02 * u(rng);
  }
  Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd creep = Eigen::VectorXd::Zero(8);
  double t = 0.0;
  for (int i = 0; i < rows; ++i) {
    const double dt = (1.0 + (jitter ? 0.3 * u(rng) : 0.0)) / 150.0;
    t += dt;
    d.t_s[static_cast<std::size_t>(i)] = t;
    if (i % 600 == 0) {
      for (int a = 0; a < 6; ++a) w(a) = 50.0 * u(rng);
    }
    const Eigen::VectorXd b = s * w;
    creep += (0.01 * b - creep) * (1.0 - std::exp(-dt / 20.0));
    d.wrench.row(i) = w.transpose();
    d.sim_mvv.row(i) = b.transpose();
    for (int c = 0; c < 8; ++c) d.real_mvv(i, c) = b(c) + creep(c) + 2e-4 * g(rng);
  }
  return d;
}

// Uniform against ±30 % jittered timestamps, same size, same run (issue 12: ≤ 3 s for 10^5
// rows × 8 channels, ≤ 20 s for 10^6).
void BM_DiagnoseClock(benchmark::State& state) {
  const auto rows = static_cast<int>(state.range(0));
  const bool jitter = state.range(1) != 0;
  const diag::DiagData data = MakeJitterData(rows, jitter);
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
    ->Iterations(1);
BENCHMARK(BM_DiagnoseClock)
    ->Args({1000000, 0})
    ->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Name("BM_DiagnoseClock1M");

}  // namespace

BENCHMARK_MAIN();
