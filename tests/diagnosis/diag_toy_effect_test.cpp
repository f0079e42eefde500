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
  e.params["warmup_half_life_s"] = s.param.value * std::log(2.0);  // derived: no σ, no range
  e.evidence = fx::Fmt("a transient decaying with τ = %.3g s", s.param.value);
  return e;
}

const EffectSpec kWarmup{.fit = &FitWarmup, .ranges = &WarmupSpecs};

/// A second toy: a gain error of one sign by its physics (0 to 5 % of the load's output).
std::vector<ParamSpec> GainSpecs(const Context& /*cx*/) {
  return {{.key = "gain_fraction",
           .lo = 0.0,
           .hi = 0.05,
           .lo_what = "none",
           .hi_what = "5 %",
           .scale = ParamScale::kLinear}};
}

std::optional<EffectFit> FitGain(const Context& cx, const Series& target) {
  const Eigen::MatrixXd& load = cx.load;
  EffectFit e;
  e.name = "toy_gain";
  e.n_params = cx.nc;
  const fx::ChannelFit f = fx::FitChannels(
      cx, target, 1, [&](int i, int c, double* x) { x[0] = load(i, c); }, &e.pred);
  e.train_sse_w = f.sse_w;
  fx::PutChannelCoef(cx, f, 0, "gain_fraction", &e);
  return e;
}

EffectSpec ToyGain() {
  EffectSpec s;
  s.fit = &FitGain;
  s.ranges = &GainSpecs;
  return s;
}

/// The same gain declared as a scale (searched in log, 0.01 % to 5 %): its pieces are judged by
/// a factor too.
std::vector<ParamSpec> GainScaleSpecs(const Context& /*cx*/) {
  return {{.key = "gain_fraction",
           .lo = 1e-4,
           .hi = 0.05,
           .lo_what = "0.01 %",
           .hi_what = "5 %",
           .scale = ParamScale::kLog}};
}

EffectSpec ToyGainScale() {
  EffectSpec s;
  s.fit = &FitGain;
  s.ranges = &GainScaleSpecs;
  return s;
}

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
  // A figure computed from the fitted ones is typed as such, with their status.
  const auto& half = Typed(typed, "warmup_half_life_s");
  EXPECT_EQ(half["status"], "resolved") << half.dump();
  EXPECT_EQ(half["derived_from"], nlohmann::json({"amplitude_mvv", "warmup_tau_s"}));
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
  // The derived half-life is no better than the τ it is computed from.
  EXPECT_EQ(Typed(typed, "warmup_half_life_s")["status"], "at_bound") << typed.dump();
}

/// 3 bridges at 100 Hz for 60 s on random load steps; real = sim·(1 + g) + noise 1e-4, g = +1 %
/// on every bridge, except from `switch_s` on, where it is `gain_after`.
DiagData GainSwitch(double switch_s, double gain_after, unsigned seed) {
  DiagData d = Warmup(1.0, seed);  // its load steps; its real columns are replaced
  std::mt19937 rng(seed + 1U);
  std::normal_distribution<double> g(0.0, 1.0);
  for (Eigen::Index i = 0; i < d.sim_mvv.rows(); ++i) {
    const double gain = d.t_s[static_cast<std::size_t>(i)] < switch_s ? 0.01 : gain_after;
    for (Eigen::Index c = 0; c < d.sim_mvv.cols(); ++c) {
      d.real_mvv(i, c) = d.sim_mvv(i, c) * (1.0 + gain) + 1e-4 * g(rng);
    }
  }
  return d;
}

// The engine's claim rule on a declared parameter whose pieces of the record disagree in sign:
// a gain of +1 % that turns to −1 % in the last of the 4 pieces fits to about +0.5 % on the whole
// record and is never claimed; the same gain held throughout is.
TEST(DiagToyEffect, PiecesThatDisagreeInSignAreNeverClaimed) {
  const EffectSpec spec = ToyGain();
  for (const double flip_s : {46.0, 1e9}) {
    const DiagData d = GainSwitch(flip_s, -0.01, 11);
    Context cx = MakeContext(d);
    auto fit = FitGain(cx, cx.resid);
    ASSERT_TRUE(fit);
    EXPECT_EQ(NotResolved(cx, *fit, spec), "");  // no pieces known yet: inside its range
    PieceSpreads(&cx, cx.resid, &*fit, spec);
    ASSERT_TRUE(fit->spread.contains("gain_fraction")) << fit->spread.dump();
    const std::string why = NotResolved(cx, *fit, spec);
    const std::string status = Typed(TypedParameters(cx, *fit, spec), "gain_fraction")["status"];
    if (flip_s < 60.0) {
      EXPECT_NE(why.find("pieces disagree (gain_fraction"), std::string::npos)
          << why << " " << fit->spread.dump();
      EXPECT_EQ(status, "pieces_disagree");
    } else {
      EXPECT_EQ(why, "") << fit->spread.dump();
      EXPECT_EQ(status, "resolved");
    }
  }
}

// Pieces of one sign of a scale: a gain of +1 % that becomes +3 % in the last of the 4 pieces (a
// factor 3, far over the noise) is not one value: never claimed, its status pieces_disagree, and
// the claim rule and the typed status say the same. A gain that becomes +1.5 % (a factor 1.5)
// scatters over the curvature σ but is one uncertain value: claimed, resolved, the scatter
// reported.
TEST(DiagToyEffect, PiecesThatDifferByMoreThanAFactorTwoAreNeverClaimed) {
  const EffectSpec spec = ToyGainScale();
  struct Case {
    double gain_after;
    bool claimed;
  };
  for (const Case c : {Case{0.03, false}, Case{0.015, true}, Case{0.01, true}}) {
    const DiagData d = GainSwitch(46.0, c.gain_after, 12);
    Context cx = MakeContext(d);
    auto fit = FitGain(cx, cx.resid);
    ASSERT_TRUE(fit);
    PieceSpreads(&cx, cx.resid, &*fit, spec);
    const std::string why = NotResolved(cx, *fit, spec);
    const nlohmann::json typed = Typed(TypedParameters(cx, *fit, spec), "gain_fraction");
    const auto& s = fit->spread["gain_fraction"];
    if (c.claimed) {
      EXPECT_EQ(why, "") << c.gain_after << " " << s.dump();
      EXPECT_EQ(typed["status"], "resolved") << typed.dump();
      EXPECT_TRUE(s["agree"].get<bool>());
      EXPECT_EQ(s["scatter_over_curvature"].get<bool>(), c.gain_after != 0.01) << s.dump();
    } else {
      EXPECT_NE(why.find("a factor"), std::string::npos) << why << " " << s.dump();
      EXPECT_EQ(typed["status"], "pieces_disagree") << typed.dump();
      EXPECT_EQ(typed["why"], why);
      EXPECT_FALSE(s["agree"].get<bool>());
    }
  }
}

}  // namespace
}  // namespace ftstack::diag
