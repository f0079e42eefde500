// Per-sample cost of the fixed-point core next to a double-precision Eigen implementation of the
// same model.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "firmware/core.hpp"

namespace {

using namespace ftstack;

constexpr int kSamples = 1024;  // cycled input set, so the loop is not a single cached value

/// Model terms of a configuration (second benchmark argument).
enum Terms : int { kLinear = 0, kSecondOrder = 1, kTemperature = 2, kBoth = 3 };

hal::AdcInfo Adc24(std::uint8_t n) {
  hal::AdcInfo a;
  a.channel_count = n;
  a.max_counts = (1 << 23) - 1;
  a.min_counts = -(1 << 23);
  a.full_scale_nvv = 3906250;
  a.rate_hz = 1000;
  return a;
}

/// A random calibration; with second order every product of two bridges (N(N+1)/2 terms), with
/// temperature a zero drift and a gain drift per bridge.
fw::FloatCalibration RandomCal(std::uint8_t n, int terms, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  fw::FloatCalibration cal{};
  cal.channel_count = n;
  for (std::size_t r = 0; r < fw::kAxes; ++r) {
    for (std::size_t c = 0; c < n; ++c) cal.matrix[r][c] = (r < 3 ? 150.0 : 6.0) * u(rng);
    cal.bias[r] = 0.1 * u(rng);
  }
  for (std::size_t c = 0; c < n; ++c) cal.offset_mvv[c] = 0.05 * u(rng);
  if ((terms & kSecondOrder) != 0) {
    for (std::uint8_t a = 0; a < n; ++a) {
      for (std::uint8_t b = a; b < n; ++b) {
        const std::size_t k = cal.product_count++;
        cal.products[k] = fw::ProductTerm{a, b};
        for (std::size_t r = 0; r < fw::kAxes; ++r) {
          cal.product_matrix[r][k] = (r < 3 ? 2.0 : 0.08) * u(rng);
        }
      }
    }
  }
  if ((terms & kTemperature) != 0) {
    cal.temperature_compensated = true;
    for (std::size_t c = 0; c < n; ++c) {
      cal.bias_slope_mvv_per_c[c] = 1e-4 * u(rng);
      cal.gain_slope_per_c[c] = 2e-4 * u(rng);
    }
  }
  return cal;
}

/// Samples whose temperature changes every `temp_every` samples (a random step of up to ±20 m°C
/// around 25 °C: a thermistor read more slowly than the bridges, or a new reading each sample
/// when temp_every is 1). Counts are random every sample.
std::vector<hal::AdcSample> RandomSamples(std::uint8_t n, std::mt19937_64& rng, int temp_every) {
  std::uniform_int_distribution<std::int32_t> d(-4000000, 4000000);
  std::uniform_int_distribution<std::int32_t> step(-20, 20);
  std::vector<hal::AdcSample> v(kSamples);
  std::int32_t t = 25000;
  for (std::size_t i = 0; i < v.size(); ++i) {
    auto& s = v[i];
    s.channel_count = n;
    for (std::size_t c = 0; c < n; ++c) s.counts[c] = d(rng);
    if (i % static_cast<std::size_t>(temp_every) == 0) {
      std::int32_t next = t;
      while (next == t) next = t + step(rng);  // a reading that differs from the last one
      t = next;
    }
    s.temperature_mdegc = t;
    s.has_temperature = true;
  }
  return v;
}

/// Samples per temperature reading in the benchmarks (third argument 0): 8 kHz bridges with a
/// thermistor read at 125 Hz. Argument 1 gives every sample a new temperature (the worst case).
constexpr int kTempEvery = 64;

int TempEvery(const benchmark::State& state) { return state.range(2) != 0 ? 1 : kTempEvery; }

bool LoadFixed(benchmark::State& state, fw::WrenchCore& core, std::uint8_t n, int terms,
               std::mt19937_64& rng) {
  fw::FixedCalibration fixed{};
  if (fw::LoadCalibration(RandomCal(n, terms, rng), Adc24(n), &fixed, nullptr) !=
      fw::LoadStatus::kOk) {
    state.SkipWithError("calibration refused");
    return false;
  }
  core.SetCalibration(fixed);
  return true;
}

// The whole per-sample path: fault checks, matrix, moving average (length 1 and 16).
void BM_FixedCore(benchmark::State& state) {
  const auto n = static_cast<std::uint8_t>(state.range(0));
  std::mt19937_64 rng(1);
  fw::WrenchCore core;
  if (!LoadFixed(state, core, n, kLinear, rng)) return;
  if (!core.SetFilterLength(static_cast<std::uint16_t>(state.range(1)))) return;
  const auto samples = RandomSamples(n, rng, kTempEvery);
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

// The model step in fixed point: counts (and temperature) → wrench, LSB.
void BM_FixedMatrix(benchmark::State& state) {
  const auto n = static_cast<std::uint8_t>(state.range(0));
  const auto terms = static_cast<int>(state.range(1));
  std::mt19937_64 rng(1);
  fw::WrenchCore core;
  if (!LoadFixed(state, core, n, terms, rng)) return;
  const auto samples = RandomSamples(n, rng, TempEvery(state));
  fw::WrenchLsb y{};
  bool sat = false;
  bool temp_range = false;
  std::size_t i = 0;
  for (auto _ : state) {
    const hal::AdcSample& s = samples[i];
    core.Apply(s.counts, s.temperature_mdegc, s.has_temperature, y, &sat, &temp_range);
    benchmark::DoNotOptimize(y);
    i = (i + 1) & (kSamples - 1);
  }
  state.SetItemsProcessed(state.iterations());
}

/// The same model in double precision with Eigen, written as one would on a board with an FPU:
/// x = counts·(mV/V per count) − offset; x' = x − α·ΔT − (γ∘x)·ΔT; features [x'; x_a·x_b];
/// wrench = [M P]·features + bias, one matrix-vector product of fixed row count and bounded,
/// run-time column count (no heap), as the fixed-point core handles any N at run time.
class DoubleCore {
 public:
  static constexpr int kMaxF = static_cast<int>(fw::kMaxChannels + fw::kMaxProducts);
  using Matrix = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxF>;
  using Features = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxF, 1>;

  explicit DoubleCore(const fw::FloatCalibration& cal, const hal::AdcInfo& adc)
      : n_(cal.channel_count), products_(cal.product_count), temp_(cal.temperature_compensated) {
    mvv_per_count_ = 1.0 / fw::CountsPerMvv(adc);
    m_.resize(6, n_ + products_);
    f_.resize(n_ + products_);
    for (int r = 0; r < 6; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      bias_(r) = cal.bias[ru];
      for (int c = 0; c < n_; ++c) m_(r, c) = cal.matrix[ru][static_cast<std::size_t>(c)];
      for (int k = 0; k < products_; ++k) {
        m_(r, n_ + k) = cal.product_matrix[ru][static_cast<std::size_t>(k)];
      }
    }
    for (int c = 0; c < n_; ++c) {
      const auto cu = static_cast<std::size_t>(c);
      offset_(c) = cal.offset_mvv[cu];
      alpha_(c) = cal.bias_slope_mvv_per_c[cu];
      gamma_(c) = cal.gain_slope_per_c[cu];
    }
    for (int k = 0; k < products_; ++k) {
      a_[static_cast<std::size_t>(k)] = cal.products[static_cast<std::size_t>(k)].a;
      b_[static_cast<std::size_t>(k)] = cal.products[static_cast<std::size_t>(k)].b;
    }
    t_ref_ = cal.temp_ref_c;
    t_min_ = cal.temp_min_c;
    t_max_ = cal.temp_max_c;
    m_dt_ = m_;
    bias_dt_ = bias_;
  }

  /// Bridge values on the stack, products from them, then the N bridge features (temperature
  /// folded in) written straight into the feature vector: plain loops for the O(N + P) steps,
  /// Eigen's matrix-vector product for the O(6·(N + P)) one.
  void Apply(const hal::AdcSample& s, Eigen::Matrix<double, 6, 1>& y) { Run<false>(s, y); }

  /// The same model with the temperature folded into the matrix and the bias once per new
  /// reading, as the fixed-point core caches it: wrench = M(ΔT)·[x; x_a·x_b] + b(ΔT) with
  /// M(ΔT)_rc = M_rc·(1 − γ_c·ΔT) and b(ΔT) = bias − Σ_c M_rc·α_c·ΔT.
  void ApplyCached(const hal::AdcSample& s, Eigen::Matrix<double, 6, 1>& y) { Run<true>(s, y); }

 private:
  template <bool kCached>
  void Run(const hal::AdcSample& s, Eigen::Matrix<double, 6, 1>& y) {
    if constexpr (kCached) {
      if (temp_ && (!cached_ || s.temperature_mdegc != cached_mdegc_)) {
        const double dt = std::clamp(s.temperature_mdegc * 1e-3, t_min_, t_max_) - t_ref_;
        bias_dt_ = bias_;
        for (int c = 0; c < n_; ++c) {
          m_dt_.col(c) = m_.col(c) * (1.0 - gamma_(c) * dt);
          bias_dt_ -= m_.col(c) * (alpha_(c) * dt);
        }
        cached_ = true;
        cached_mdegc_ = s.temperature_mdegc;
      }
    }
    std::array<double, fw::kMaxChannels> x;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    for (int c = 0; c < n_; ++c) {
      const double xc = s.counts[static_cast<std::size_t>(c)] * mvv_per_count_ - offset_(c);
      x[static_cast<std::size_t>(c)] = xc;
      f_(c) = xc;
    }
    for (int k = 0; k < products_; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      f_(n_ + k) = x[a_[ku]] * x[b_[ku]];
    }
    if constexpr (kCached) {
      y.noalias() = m_dt_ * f_;
      y += bias_dt_;
    } else {
      if (temp_) {
        const double dt = std::clamp(s.temperature_mdegc * 1e-3, t_min_, t_max_) - t_ref_;
        for (int c = 0; c < n_; ++c) {
          const double xc = x[static_cast<std::size_t>(c)];
          f_(c) = xc - dt * (alpha_(c) + gamma_(c) * xc);
        }
      }
      y.noalias() = m_ * f_;
      y += bias_;
    }
  }

  int n_;
  int products_;
  bool temp_;
  double mvv_per_count_ = 0;
  Matrix m_;
  Matrix m_dt_;  ///< ApplyCached: m_ at cached_mdegc_
  Eigen::Matrix<double, 6, 1> bias_dt_;
  bool cached_ = false;
  std::int32_t cached_mdegc_ = 0;
  Features f_;
  Eigen::Matrix<double, 6, 1> bias_;
  Eigen::Matrix<double, fw::kMaxChannels, 1> offset_, alpha_, gamma_;
  std::array<std::uint8_t, fw::kMaxProducts> a_{}, b_{};
  double t_ref_ = 20, t_min_ = -20, t_max_ = 80;
};

/// The double model per sample (kCached: with the per-temperature cache, DoubleCore::ApplyCached).
template <bool kCached>
void EigenDouble(benchmark::State& state) {
  const auto n = static_cast<std::uint8_t>(state.range(0));
  const auto terms = static_cast<int>(state.range(1));
  std::mt19937_64 rng(1);
  DoubleCore core(RandomCal(n, terms, rng), Adc24(n));
  const auto samples = RandomSamples(n, rng, TempEvery(state));
  Eigen::Matrix<double, 6, 1> y;
  std::size_t i = 0;
  for (auto _ : state) {
    if constexpr (kCached) {
      core.ApplyCached(samples[i], y);
    } else {
      core.Apply(samples[i], y);
    }
    benchmark::DoNotOptimize(y);
    i = (i + 1) & (kSamples - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
void BM_EigenDouble(benchmark::State& state) { EigenDouble<false>(state); }

// Every configuration (N, terms, temperature every 64 samples) for fixed point and for double,
// measured in the same run; with temperature terms also a new temperature every sample.
void Configurations(benchmark::internal::Benchmark* b) {
  for (int n : {6, 8}) {
    for (int terms : {kLinear, kSecondOrder, kTemperature, kBoth}) b->Args({n, terms, 0});
  }
  for (int n : {6, 8}) {
    for (int terms : {kTemperature, kBoth}) b->Args({n, terms, 1});
  }
}
BENCHMARK(BM_FixedMatrix)->Apply(Configurations);
BENCHMARK(BM_EigenDouble)->Apply(Configurations);

// The double model with the fixed-point core's per-temperature cache (temperature terms only):
// like with like for the temperature configurations.
void BM_EigenDoubleCached(benchmark::State& state) { EigenDouble<true>(state); }
BENCHMARK(BM_EigenDoubleCached)->Args({6, 2, 0})->Args({6, 3, 0})->Args({8, 2, 0})->Args({8, 3, 0});

}  // namespace

BENCHMARK_MAIN();
