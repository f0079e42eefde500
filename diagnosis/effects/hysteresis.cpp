// hysteresis: one rate-independent operator (Dahl or play, width searched) per bridge, or a
// Preisach superposition of relays on a grid of thresholds on each bridge's own load (contains the
// Prandtl–Ishlinskii sums of play operators of those widths), weights fitted per bridge.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

std::vector<ParamSpec> fx::HysteresisSpecs(const Context& /*cx*/) {
  return {{.key = "travel_fraction",
           .lo = 0.002,
           .hi = 2.0,
           .lo_what = "0.2 % of the load's travel (below the noise of a loop)",
           .hi_what = "twice the load's travel (a wider operator never reverses)",
           .unit = "",
           .grid_points = 11,
           .golden_steps = 10}};
}

std::optional<EffectFit> FitHysteresisOperator(const Context& cx, const Series& target) {
  // Two rate-independent operators on each bridge's own load history: Dahl (exponential approach
  // after a reversal) and play/backlash (linear approach, then flat); width searched for each.
  Mat z(cx.n, cx.nc);
  auto build = [&](double log_w, bool play) {
    for (int c = 0; c < cx.nc; ++c) {
      const double width = std::exp(log_w) * std::max(cx.load_range(c), 1e-12);
      if (play) {
        PlayOperator(cx.load.col(c).data(), static_cast<std::size_t>(cx.n), width, z.col(c).data());
      } else {
        DahlOperator(cx.load.col(c).data(), static_cast<std::size_t>(cx.n), width, z.col(c).data());
      }
    }
  };
  auto sse_for = [&](double log_w, bool play) {
    build(log_w, play);
    return SearchSse(cx, target, z);
  };
  EffectFit best;
  for (bool play : {false, true}) {
    const SolvedParam s =
        SolveParameter(HysteresisSpecs(cx)[0], [&](double v) { return sse_for(v, play); });
    const double lw = s.coord;
    EffectFit e;
    e.name = "hysteresis";
    e.variant = play ? "rate-independent play (backlash) operator on each bridge's load"
                     : "rate-independent Dahl operator on each bridge's load";
    e.n_params = cx.nc + 1;
    build(lw, play);
    const auto f = FitChannels(
        cx, target, 1, [&](int i, int c, double* x) { x[0] = z(i, c); }, &e.pred);
    e.train_sse_w = f.sse_w;
    if (!best.name.empty() && best.train_sse_w <= e.train_sse_w) continue;
    PutChannelCoef(cx, f, 0, "half_width_mvv", &e);
    e.params["travel_fraction"] = std::exp(lw);
    e.sigma["travel_fraction"] = JsonNum(s.sigma);
    best = std::move(e);
  }
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  const double h = best.params["half_width_mvv"][static_cast<std::size_t>(c)].get<double>();
  best.evidence = Fmt(
      "at the same load b%d reads %.3g mV/V differently when the load came from above than from "
      "below (%.1f σ), constant during holds, r = %.2f",
      c, 2.0 * std::fabs(h), 2.0 * std::fabs(h) / cx.sigma(c), RowCorr(cx, target, best.pred, c));
  return best;
}

}  // namespace ftstack::diag

namespace ftstack::diag {
namespace {

/// Preisach relays on a grid of kLevels load levels (quantiles of the bridge's load): one relay
/// for every pair down < up, switching to +1 at or above `up` and to −1 at or below `down`;
/// unknown (0) until the input first reaches one of its thresholds.
constexpr int kLevels = 8;
constexpr int kRelays = kLevels * (kLevels - 1) / 2;

struct RelayGrid {
  std::array<double, kRelays> up{};
  std::array<double, kRelays> down{};
  std::array<double, kRelays> state{};
  std::array<double, kLevels> level{};  ///< the thresholds, ascending
  int band = -1;  ///< band of the last input (levels ≤ x, levels < x); −1: none since a reset
  void Step(double x) {
    for (int j = 0; j < kRelays; ++j) {
      if (x >= up[static_cast<std::size_t>(j)]) state[static_cast<std::size_t>(j)] = 1.0;
      if (x <= down[static_cast<std::size_t>(j)]) state[static_cast<std::size_t>(j)] = -1.0;
    }
  }
  /// Step, skipped while the input stays in the band of the last step: every comparison of Step
  /// depends on x only through its band, and repeating the last assignments changes nothing.
  /// Returns whether Step ran.
  bool StepBand(double x) {
    int at_or_below = 0;
    int below = 0;
    for (const double l : level) {
      at_or_below += l <= x ? 1 : 0;
      below += l < x ? 1 : 0;
    }
    const int b = at_or_below * (kLevels + 1) + below;
    if (b == band) return false;
    band = b;
    Step(x);
    return true;
  }
  void Reset() {
    state.fill(0.0);
    band = -1;
  }
};

RelayGrid MakeGrid(const double* x, std::size_t n) {
  std::array<double, kLevels> level{};
  std::vector<double> work(x, x + n);
  MidQuantiles(&work, kLevels, level.data());
  RelayGrid g;
  g.level = level;
  int j = 0;
  for (int lo = 0; lo < kLevels; ++lo) {
    for (int hi = lo + 1; hi < kLevels; ++hi, ++j) {
      g.down[static_cast<std::size_t>(j)] = level[static_cast<std::size_t>(lo)];
      g.up[static_cast<std::size_t>(j)] = level[static_cast<std::size_t>(hi)];
    }
  }
  return g;
}

/// The lower training BIC of two fits (either may be absent).
std::optional<EffectFit> LowerBic(const Context& cx, std::optional<EffectFit> a,
                                  std::optional<EffectFit> b) {
  if (!a) return b;
  if (!b) return a;
  const double log_n = std::log(std::max<double>(2.0, static_cast<double>(cx.n_train)));
  // Two returns, not a conditional expression: each moves its fit (a ?: would copy n × N).
  if (a->train_sse_w + a->n_params * log_n <= b->train_sse_w + b->n_params * log_n) return a;
  return b;
}

std::optional<EffectFit> FitHysteresisPreisach(const Context& cx, const Series& target);

}  // namespace

std::optional<EffectFit> FitHysteresisFamily(const Context& cx, const Series& target) {
  // In the load path (operators on the wrench axes, seen through the sensitivity) or in each
  // bridge (one operator, or a Preisach sum of relays): the lowest training BIC.
  auto best = LowerBic(cx, FitHysteresisAxes(cx, target), FitHysteresisOperator(cx, target));
  if (cx.n < 4 * kRelays) return best;
  return LowerBic(cx, best, FitHysteresisPreisach(cx, target));
}

std::optional<EffectFit> RefitHysteresis(const Context& cx, const Series& target,
                                         const EffectFit& near, bool /*uncertainty*/) {
  // The sub-family near's fit came from, searched again (its σ are cheap: always computed).
  if (near.variant.find("wrench axis") != std::string::npos) return FitHysteresisAxes(cx, target);
  if (near.variant.rfind("Preisach", 0) == 0 && cx.n >= 4 * kRelays) {
    return FitHysteresisPreisach(cx, target);
  }
  return FitHysteresisOperator(cx, target);
}

namespace {

std::optional<EffectFit> FitHysteresisPreisach(const Context& cx, const Series& target) {
  const auto n = static_cast<std::size_t>(cx.n);
  EffectFit e;
  e.name = "hysteresis";
  e.variant =
      "Preisach: weighted sum of 28 relays (thresholds on 8 quantiles of the "
      "bridge's load) on each bridge's load";
  e.n_params = cx.nc * kRelays;  // relay weights (a relay is 0 until its state is known)
  e.pred = Series::Zero(cx.n, cx.nc);
  nlohmann::json weights = nlohmann::json::array();
  nlohmann::json sigmas = nlohmann::json::array();
  double sse_w = 0.0;
  constexpr int p = kRelays;
  for (int c = 0; c < cx.nc; ++c) {
    const double* load = cx.load.col(c).data();
    const RelayGrid start = MakeGrid(load, n);
    NormalEq ne(p);
    double x[p];
    RelayGrid g = start;
    // Streamed: no n × relays matrix is held. Weights from every k-th training row on long
    // records (k = the search stride, ~12 000 rows): the relay states change only at threshold
    // crossings, so little is lost.
    const auto stride = static_cast<std::size_t>(cx.search_stride);
    ForRowsWithTraining(cx, 0, static_cast<int>(n), [&](int row, bool train) {
      const auto i = static_cast<std::size_t>(row);
      if (!cx.restart.empty() && cx.restart[i] != 0) g.Reset();
      g.StepBand(load[i]);
      if (!train || i % stride != 0) return;
      for (int j = 0; j < kRelays; ++j) x[j] = g.state[static_cast<std::size_t>(j)];
      ne.Add(x, target(row, c));
    });
    const NormalEq::Result r = ne.Solve();
    const double var = r.rows > p ? r.sse / (r.rows - p) : 0.0;
    nlohmann::json w = nlohmann::json::array();
    nlohmann::json sw = nlohmann::json::array();
    for (int j = 0; j < kRelays; ++j) {
      w.push_back(r.beta(j));  // half-height of the relay's loop, mV/V
      sw.push_back(std::sqrt(std::max(0.0, r.cov_unit(j, j) * var)));
    }
    weights.push_back(w);
    sigmas.push_back(sw);
    g = start;
    double v = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!cx.restart.empty() && cx.restart[i] != 0) g.Reset();
      if (g.StepBand(load[i])) {  // else the states, and so v, are those of the last row
        v = 0.0;
        for (int j = 0; j < kRelays; ++j) v += r.beta(j) * g.state[static_cast<std::size_t>(j)];
      }
      e.pred(static_cast<Eigen::Index>(i), c) = v;
    }
    sse_w += r.sse * cx.weight(c) * cx.search_stride;
  }
  e.train_sse_w = sse_w;
  e.params["relay_levels"] = kLevels;
  e.params["loop_half_height_mvv"] = weights;
  e.sigma["loop_half_height_mvv"] = sigmas;
  e.evidence = fx::ReversalEvidence(cx, &e) +
               Fmt(", a sum of %d relay loops, constant during holds", kRelays);
  return e;
}

}  // namespace
}  // namespace ftstack::diag

namespace ftstack::diag {

EffectSpec HysteresisPlugin() {
  return {.kind = EffectKind::kHysteresis,
          .traits = kLoadHistory,
          .confounders = kConfoundersOfLoadHistory,
          .fit = &FitHysteresisFamily,
          .refit = &RefitHysteresis,
          .cost = 2,
          .ranges = &HysteresisSpecs};
}

}  // namespace ftstack::diag

namespace ftstack::diag::fx {

std::string ReversalEvidence(const Context& cx, EffectFit* e) {
  const int c = DominantChannel(cx, e->pred);
  e->channels = ChannelsAboveNoise(cx, e->pred);
  const Eigen::VectorXd col = e->pred.col(c).cast<double>();
  const double range = col.maxCoeff() - col.minCoeff();
  return Fmt(
      "at the same load b%d reads up to %.3g mV/V differently depending on the load's past "
      "reversals (%.1f σ)",
      c, range, range / cx.sigma(c));
}

}  // namespace ftstack::diag::fx
