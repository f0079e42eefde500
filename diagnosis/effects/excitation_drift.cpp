// excitation_drift: a common relative sensitivity wander in time (a hat spline times the load),
// knot count chosen by BIC.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The knot counts excitation_drift tries (k intervals, k + 1 knots), in order.
constexpr int kExcitationIntervals[] = {1, 2, 3, 4, 6, 8, 12, 16, 24, 32};

/// excitation_drift with a hat spline of k intervals for k in `ks` (stopping after two rises of
/// the training BIC in a row): the lowest-BIC fit.
std::optional<EffectFit> ExcitationSearch(const Context& cx, const Series& target,
                                          const std::vector<int>& ks) {
  const auto& d = *cx.data;
  const double duration = d.t_s.back() - d.t_s.front();
  double best_bic = std::numeric_limits<double>::infinity();
  EffectFit best;
  int worse = 0;
  std::vector<int> hat_j(static_cast<std::size_t>(cx.n));
  std::vector<double> hat_fr(static_cast<std::size_t>(cx.n));
  for (int k : ks) {
    if (duration / k < 3.0 * cx.block_s) break;
    const HatBasis hb = MakeHat(cx, k);
    for (int i = 0; i < cx.n; ++i) {  // once per row, not per row and channel
      const auto u = static_cast<std::size_t>(i);
      hb.At(d.t_s[u], &hat_j[u], &hat_fr[u]);
    }
    NormalEq ne(k + 1);
    for (int c = 0; c < cx.nc; ++c) {
      ForTrainingRows(cx, 0, cx.n, [&](int i) {
        const int j = hat_j[static_cast<std::size_t>(i)];
        const double fr = hat_fr[static_cast<std::size_t>(i)];
        const double s = cx.sim_mvv(i, c);
        const int idx[2] = {j, j + 1};
        const double val[2] = {(1.0 - fr) * s, fr * s};
        ne.AddSparse(idx, val, 2, target(i, c), cx.weight(c));
      });
    }
    const auto r = ne.Solve();
    const int p = k + 1;
    const double bic = r.sse + p * Penalty(cx);
    if (bic >= best_bic) {
      if (++worse >= 2) break;
    } else {
      worse = 0;
      best_bic = bic;
      EffectFit e;
      e.name = "excitation_drift";
      e.n_params = p;
      e.train_sse_w = r.sse;
      best.pred = Series();  // replaced by e below: one n × N prediction at a time
      e.pred.resize(cx.n, cx.nc);
      Vec factor(cx.n);
      for (int i = 0; i < cx.n; ++i) {
        const int j = hat_j[static_cast<std::size_t>(i)];
        const double fr = hat_fr[static_cast<std::size_t>(i)];
        factor(i) = r.beta(j) * (1.0 - fr) + r.beta(j + 1) * fr;
        for (int c = 0; c < cx.nc; ++c) e.pred(i, c) = factor(i) * cx.sim_mvv(i, c);
      }
      e.params["knots"] = p;
      e.params["factor_min"] = 1.0 + factor.minCoeff();
      e.params["factor_max"] = 1.0 + factor.maxCoeff();
      e.variant = Fmt("common factor, hat spline with %d knots", p);
      best = std::move(e);
    }
  }
  if (best.name.empty()) return std::nullopt;
  best.channels = ActiveChannels(cx, best.pred);
  best.evidence =
      Fmt("every channel is scaled by one common factor drifting between %.5f and %.5f over time "
          "(%d channels agree)",
          best.params["factor_min"].get<double>(), best.params["factor_max"].get<double>(),
          static_cast<int>(best.channels.size()));
  return best;
}

}  // namespace

std::optional<EffectFit> FitExcitation(const Context& cx, const Series& target) {
  // A ratiometric converter's reference follows the excitation: its drift cancels in every
  // reading, and a common gain that wanders there is some other physics (a creep within holds).
  if (cx.data->real_ratiometric) return std::nullopt;
  return ExcitationSearch(
      cx, target,
      std::vector<int>(std::begin(kExcitationIntervals), std::end(kExcitationIntervals)));
}

std::optional<EffectFit> RefitExcitation(const Context& cx, const Series& target,
                                         const EffectFit& near, bool /*uncertainty*/) {
  if (cx.data->real_ratiometric) return std::nullopt;
  // The knot count of near and its two neighbours in the list.
  const int k_near = near.params.value("knots", 0) - 1;
  const auto* it =
      std::find(std::begin(kExcitationIntervals), std::end(kExcitationIntervals), k_near);
  if (it == std::end(kExcitationIntervals)) return FitExcitation(cx, target);
  std::vector<int> ks;
  if (it != std::begin(kExcitationIntervals)) ks.push_back(*(it - 1));
  ks.push_back(*it);
  if (it + 1 != std::end(kExcitationIntervals)) ks.push_back(*(it + 1));
  return ExcitationSearch(cx, target, ks);
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ExcitationDriftPlugin() {
  return {.kind = EffectKind::kExcitationDrift,
          .traits = kTimeBased,
          .confounders = kConfoundersOfTime,
          .fit = &fx::FitExcitation,
          .refit = &fx::RefitExcitation,
          .cost = 2};
}

}  // namespace ftstack::diag
