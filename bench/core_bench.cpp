// Per-sample cost of the fixed-point core next to a plain double-precision Eigen implementation.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "firmware/core.hpp"

namespace {

using namespace ftstack;

constexpr int kSamples = 1024;  // cycled input set, so the loop is not a single cached value

hal::AdcInfo Adc24(std::uint8_t n) {
  hal::AdcInfo a;
  a.channel_count = n;
  a.max_counts = (1 << 23) - 1;
  a.min_counts = -(1 << 23);
  a.full_scale_nvv = 3906250;
  a.rate_hz = 1000;
  return a;
}

fw::FloatCalibration RandomCal(std::uint8_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  fw::FloatCalibration cal{};
  cal.channel_count = n;
  for (std::size_t r = 0; r < fw::kAxes; ++r) {
    for (std::size_t c = 0; c < n; ++c) cal.matrix[r][c] = (r < 3 ? 150.0 : 6.0) * u(rng);
    cal.bias[r] = 0.1 * u(rng);
  }
  return cal;
}

std::vector<hal::AdcSample> RandomSamples(std::uint8_t n, std::mt19937_64& rng) {
  std::uniform_int_distribution<std::int32_t> d(-4000000, 4000000);
  std::vector<hal::AdcSample> v(kSamples);
  for (auto& s : v) {
    s.channel_count = n;
    for (std::size_t c = 0; c < n; ++c) s.counts[c] = d(rng);
  }
  return v;
}

// The whole per-sample path: fault checks, matrix, moving average (length 1 and 16).
void BM_FixedCore(benchmark::State& state) {
  const auto n = static_cast<std::uint8_t>(state.range(0));
  std::mt19937_64 rng(1);
  fw::FixedCalibration fixed{};
  if (fw::LoadCalibration(RandomCal(n, rng), Adc24(n), &fixed, nullptr) != fw::LoadStatus::kOk) {
    state.SkipWithError("calibration refused");
    return;
  }
  fw::WrenchCore core;
  core.SetCalibration(fixed);
  if (!core.SetFilterLength(static_cast<std::uint16_t>(state.range(1)))) return;
  const auto samples = RandomSamples(n, rng);
  fw::CoreOutput out{};
  std::size_t i = 0;
  for (auto _ : state) {
    core.Process(samples[i], false, out);
    benchmark::DoNotOptimize(out);
    i = (i + 1) & (kSamples - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FixedCore)->Args({6, 1})->Args({8, 1})->Args({6, 16})->Args({8, 16});

// The matrix step alone in fixed point.
void BM_FixedMatrix(benchmark::State& state) {
  const auto n = static_cast<std::uint8_t>(state.range(0));
  std::mt19937_64 rng(1);
  fw::FixedCalibration fixed{};
  if (fw::LoadCalibration(RandomCal(n, rng), Adc24(n), &fixed, nullptr) != fw::LoadStatus::kOk) {
    state.SkipWithError("calibration refused");
    return;
  }
  fw::WrenchCore core;
  core.SetCalibration(fixed);
  const auto samples = RandomSamples(n, rng);
  fw::WrenchLsb y{};
  bool sat = false;
  std::size_t i = 0;
  for (auto _ : state) {
    core.Apply(samples[i].counts, y, &sat);
    benchmark::DoNotOptimize(y);
    i = (i + 1) & (kSamples - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FixedMatrix)->Arg(6)->Arg(8);

// Plain double precision with Eigen: counts → mV/V → M·(x − offset) + bias.
void BM_EigenDouble(benchmark::State& state) {
  const auto n = static_cast<int>(state.range(0));
  std::mt19937_64 rng(1);
  const fw::FloatCalibration cal = RandomCal(static_cast<std::uint8_t>(n), rng);
  Eigen::Matrix<double, 6, Eigen::Dynamic> m(6, n);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < n; ++c)
      m(r, c) = cal.matrix[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  }
  Eigen::Matrix<double, 6, 1> bias;
  for (int r = 0; r < 6; ++r) bias(r) = cal.bias[static_cast<std::size_t>(r)];
  const Eigen::VectorXd offset = Eigen::VectorXd::Zero(n);
  const double mvv_per_count = 3.90625 / 8388607.0;
  const auto samples = RandomSamples(static_cast<std::uint8_t>(n), rng);
  Eigen::VectorXd x(n);
  Eigen::Matrix<double, 6, 1> y;
  std::size_t i = 0;
  for (auto _ : state) {
    for (int c = 0; c < n; ++c)
      x(c) = samples[i].counts[static_cast<std::size_t>(c)] * mvv_per_count;
    y.noalias() = m * (x - offset);
    y += bias;
    benchmark::DoNotOptimize(y);
    i = (i + 1) & (kSamples - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EigenDouble)->Arg(6)->Arg(8);

}  // namespace

BENCHMARK_MAIN();
