// creep: a first-order lag of each bridge's load, τ searched.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {

namespace {

/// near's parameter `key` as log, or NaN when it has none.
double LogParam(const EffectFit* near, const char* key) {
  if (near == nullptr || !near->params.contains(key) || !near->params[key].is_number()) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double v = near->params[key].get<double>();
  return v > 0 ? std::log(v) : std::numeric_limits<double>::quiet_NaN();
}

/// argmin of f: on 5 points 0.25 apart around `start` (8 golden steps) when it is finite and the
/// minimum is inside that window, else on `grid` (12 golden steps). [lo, hi] bounds the window.
double WindowOrGrid(const std::function<double(double)>& f, double start,
                    const std::vector<double>& grid, double lo, double hi) {
  if (std::isfinite(start)) {
    std::vector<double> local;
    for (int j = -2; j <= 2; ++j) local.push_back(std::clamp(start + 0.25 * j, lo, hi));
    const double x = MinimizeOnGrid(f, local, 8, nullptr);
    const bool edge = (x <= local.front() + 0.125 && local.front() > lo) ||
                      (x >= local.back() - 0.125 && local.back() < hi);
    if (!edge) return x;
  }
  return MinimizeOnGrid(f, grid, 12, nullptr);
}

/// The standard's figures, channels and evidence of a finished creep fit (one or two τ).
void FinishCreep(const Context& cx, const Series& target, bool two, const std::vector<double>& tau,
                 const std::vector<double>& tau_sigma, const ChannelFit& f, bool gamma,
                 EffectFit* e) {
  CreepOimlR60(cx, tau, tau_sigma, f, gamma, e);
  e->channels = ActiveChannels(cx, e->pred);
  const int c = DominantChannel(cx, e->pred);
  if (two) {
    const auto k = static_cast<std::size_t>(c);
    e->evidence =
        Fmt("during load holds b%d keeps moving toward a new value along two exponentials, τ1 = "
            "%.1f s (%.2f %% of the load) and τ2 = %.1f s (%.2f %%), and recovers after "
            "unloading, r = %.2f",
            c, tau[0], 100.0 * e->params["fraction1"][k].get<double>(), tau[1],
            100.0 * e->params["fraction2"][k].get<double>(), RowCorr(cx, target, e->pred, c));
    return;
  }
  e->evidence =
      Fmt("during load holds b%d keeps moving toward a new value with τ = %.1f s (%.2f %% of the "
          "load) and recovers after unloading, r = %.2f",
          c, e->params["tau_s"].get<double>(),
          100.0 * e->params["fraction"][static_cast<std::size_t>(c)].get<double>(),
          RowCorr(cx, target, e->pred, c));
}

}  // namespace

std::optional<EffectFit> CreepSearch(const Context& cx, const Series& target, const EffectFit* near,
                                     bool uncertainty) {
  EffectFit best;
  ChannelFit best_f;
  bool best_gamma = false;
  // A refit of a two-τ fit stays two-τ, from its pair (the one-τ baseline is not searched); the
  // one-τ search below runs only when the pair now fails its own checks.
  const double start[2] = {LogParam(near, "tau1_s"), LogParam(near, "tau2_s")};
  const bool near_two = std::isfinite(start[0]) && std::isfinite(start[1]);
  std::vector<double> taus;
  std::vector<double> tau_sigmas;
  if (near_two && FitCreepTwo(cx, target, start[0], std::numeric_limits<double>::infinity(), &best,
                              &taus, &tau_sigmas, &best_f, &best_gamma, start, uncertainty)) {
    FinishCreep(cx, target, true, taus, tau_sigmas, best_f, best_gamma, &best);
    return best;
  }
  const auto& d = *cx.data;
  const double duration = d.t_s.back() - d.t_s.front();
  // The searches read every search_stride-th row: the lagged load is kept only there (memory: a
  // compact buffer instead of n × N); the final fits stream it over every row.
  const std::vector<int> rows = StrideRows(cx);
  const int st = cx.search_stride;
  Mat lp;
  auto sse_for = [&](double log_tau, bool gamma) {
    LowPassLoadRows(cx, std::exp(log_tau), rows, &lp);
    if (gamma) {
      return FitChannels(
                 cx, target, 2,
                 [&](int i, int c, double* x) {
                   x[0] = lp(i / st, c);
                   x[1] = cx.load(i, c);
                 },
                 nullptr, nullptr, st)
                 .sse_w *
             st;
    }
    return SearchSse(cx, target, lp, true);
  };
  std::vector<double> grid;
  const double lo = std::log(std::max(3.0 * cx.dt, 0.2));
  const double hi = std::log(std::max(duration, 1.0));
  for (int j = 0; j <= 12; ++j) grid.push_back(lo + (hi - lo) * j / 12.0);
  double best_bic = std::numeric_limits<double>::infinity();
  // τ is searched with the plain model; the variant with a gain term reuses it. Near a fit: 5
  // points 0.25 apart in log τ around its τ (τ1 of a two-τ fit: the one-τ model is then only the
  // baseline the pair must beat), the full grid when the optimum is on the window's edge.
  const double near_lt =
      std::isfinite(LogParam(near, "tau_s")) ? LogParam(near, "tau_s") : LogParam(near, "tau1_s");
  const double lt =
      WindowOrGrid([&](double v) { return sse_for(v, false); }, near_lt, grid, lo, hi);
  const double tau = std::exp(lt);
  // Both variants' fits over every row in one streamed pass of LP_τ[load].
  ChannelSums sums[2] = {ChannelSums(cx, 1), ChannelSums(cx, 2)};
  ForLaggedLoad(cx, &tau, 1, [&](int i, int c, const double* lag) {
    if (!cx.train[static_cast<std::size_t>(i)]) return;
    const double x[2] = {lag[0], cx.load(i, c)};
    sums[0].Add(c, x, target(i, c));
    sums[1].Add(c, x, target(i, c));
  });
  for (bool gamma : {false, true}) {
    const int p = cx.nc * (gamma ? 2 : 1) + 1;
    EffectFit e;
    e.name = "creep";
    e.variant = gamma ? "first-order creep with a gain term" : "first-order creep";
    e.n_params = p;
    const double sl = uncertainty
                          ? CurvatureSigma([&](double v) { return sse_for(v, gamma); }, lt, 0.02)
                          : std::numeric_limits<double>::quiet_NaN();
    const ChannelFit f = sums[gamma ? 1 : 0].Solve(cx);
    e.train_sse_w = f.sse_w;
    const double bic = f.sse_w + p * Penalty(cx);
    if (bic >= best_bic) continue;
    best_bic = bic;
    e.params["tau_s"] = tau;
    e.sigma["tau_s"] = JsonNum(tau * sl);
    PutChannelCoef(cx, f, 0, "fraction", &e);
    best = std::move(e);
    best_f = f;
    best_gamma = gamma;
  }
  lp = Mat();
  // The kept variant's prediction, streamed.
  PredictStreamed(
      cx, best_f, best_gamma ? 2 : 1, [&](auto visit) { ForLaggedLoad(cx, &tau, 1, visit); },
      [&](int i, int c, const double* lag, double* x) {
        x[0] = lag[0];
        if (best_gamma) x[1] = cx.load(i, c);
      },
      &best.pred);
  taus = {std::exp(lt)};
  tau_sigmas = {best.sigma["tau_s"].is_number() ? best.sigma["tau_s"].get<double>() : 0.0};
  // The two-τ variant: searched in full alone, not in a refit (a refit keeps the variant class its
  // start found).
  const bool two = near == nullptr && FitCreepTwo(cx, target, lt, best_bic, &best, &taus,
                                                  &tau_sigmas, &best_f, &best_gamma, nullptr, true);
  FinishCreep(cx, target, two, taus, tau_sigmas, best_f, best_gamma, &best);
  return best;
}

}  // namespace ftstack::diag::fx
