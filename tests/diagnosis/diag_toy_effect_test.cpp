// A toy effect added in one file's worth of code: it declares its parameter and gives its feature;
// the engine searches, bounds, gives σ and status, and types the parameter for the report. The
// data come from a closed-form generator here (a warm-up transient a_c·e^(−t/τ) on a random load).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/solve_separable.hpp"

namespace ftstack::diag {
namespace {

// --- the toy effect: what an effect file holds -----------------------------------------------

/// A warm-up transient's time constant: 1 s to 20 s (the toy's physics).
std::vector<ParamSpec> WarmupSpecs(const Context& /*cx*/) {
  return {{.key = "warmup_tau_s",
           .lo = 1.0,
           .hi = 20.0,
           .lo_what = "1 s",
           .hi_what = "20 s",
           .unit = "s",
           .grid_points = 9,
           .golden_steps = 12}};
}

std::optional<EffectFit> FitWarmup(const Context& cx, const Series& target) {
  const std::vector<double>& t = cx.data->t_s;
  const SeparableSolution s = SolveSeparable(
      cx, target, WarmupSpecs(cx)[0], 1, [&](double tau, int i, int /*c*/, double* x) {
        x[0] = std::exp(-t[static_cast<std::size_t>(i)] / tau);
      });
  EffectFit e;
  e.name = "toy_warmup";
  e.n_params = cx.nc + 1;
  e.pred = s.pred;
  e.train_sse_w = s.linear.sse_w;
  e.params["warmup_tau_s"] = s.param.value;
  e.sigma["warmup_tau_s"] = fx::JsonNum(s.param.sigma);
  fx::PutChannelCoef(cx, s.linear, 0, "amplitude_mvv", &e);
  e.evidence = fx::Fmt("a transient decaying with τ = %.3g s", s.param.value);
  return e;
}

const EffectSpec kWarmup{.fit = &FitWarmup, .ranges = &WarmupSpecs};

// --- the test ---------------------------------------------------------------------------------

/// 3 bridges at 100 Hz for 60 s on random load steps; real = sim + a_c·e^(−t/τ) + noise 1e-3.
DiagData Warmup(double tau_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 6000;
  const int nc = 3;
  const double a[nc] = {0.05, -0.03, 0.02};
  DiagData d;
  d.sim_mvv.resize(n, nc);
  d.real_mvv.resize(n, nc);
  Eigen::VectorXd load = Eigen::VectorXd::Zero(nc);
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    if (i % 400 == 0) {
      for (int c = 0; c < nc; ++c) load(c) = 0.5 * g(rng);
    }
    d.t_s.push_back(t);
    for (int c = 0; c < nc; ++c) {
      d.sim_mvv(i, c) = load(c);
      d.real_mvv(i, c) = load(c) + a[c] * std::exp(-t / tau_s) + 1e-3 * g(rng);
    }
  }
  return d;
}

const nlohmann::json& Typed(const nlohmann::json& list, const std::string& key) {
  for (const auto& p : list) {
    if (p["key"] == key) return p;
  }
  static const nlohmann::json kNull;
  return kNull;
}

TEST(DiagToyEffect, SearchedInsideItsRangeAndTyped) {
  const DiagData d = Warmup(5.0, 7);
  const Context cx = MakeContext(d);
  const auto fit = FitWarmup(cx, cx.resid);
  ASSERT_TRUE(fit);
  const double tau = fit->params["warmup_tau_s"].get<double>();
  const double sigma = fit->sigma["warmup_tau_s"].get<double>();
  EXPECT_GT(sigma, 0.0);
  EXPECT_LT(std::fabs(tau - 5.0), std::max(4.0 * sigma, 0.05)) << tau << " ± " << sigma;
  EXPECT_EQ(NotResolved(cx, *fit, kWarmup), "");
  const nlohmann::json typed = TypedParameters(cx, *fit, kWarmup);
  const auto& p = Typed(typed, "warmup_tau_s");
  ASSERT_FALSE(p.is_null()) << typed.dump();
  EXPECT_EQ(p["unit"], "s");
  EXPECT_EQ(p["status"], "resolved");
  EXPECT_EQ(p["range"], nlohmann::json({1.0, 20.0}));
  EXPECT_DOUBLE_EQ(p["value"].get<double>(), tau);
  EXPECT_TRUE(p["spread"].is_null());
  EXPECT_TRUE(p["spread_why"].is_string());
  // The linear amplitudes: the generator's, and typed too (no declaration: status by their σ).
  const auto& amp = Typed(typed, "amplitude_mvv");
  ASSERT_FALSE(amp.is_null());
  EXPECT_NEAR(fit->params["amplitude_mvv"][0].get<double>(), 0.05, 2e-3);
  EXPECT_EQ(amp["status"], "resolved");
}

TEST(DiagToyEffect, TruthOutsideItsRangeEndsAtTheBoundAndIsNotResolved) {
  const DiagData d = Warmup(300.0, 8);  // far slower than the declared 20 s
  const Context cx = MakeContext(d);
  const auto fit = FitWarmup(cx, cx.resid);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->params["warmup_tau_s"].get<double>(), 20.0, 20.0 * 0.02);
  const std::string why = NotResolved(cx, *fit, kWarmup);
  EXPECT_NE(why.find("upper bound (20 s"), std::string::npos) << why;
  const nlohmann::json typed = TypedParameters(cx, *fit, kWarmup);
  const auto& p = Typed(typed, "warmup_tau_s");
  ASSERT_FALSE(p.is_null()) << typed.dump();
  EXPECT_EQ(p["status"], "at_bound");
}

}  // namespace
}  // namespace ftstack::diag
