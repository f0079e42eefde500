// zero_drift: a smooth function of time per bridge (hat splines, knots chosen by BIC).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

// Smooth functions of time per channel (hat splines), knots chosen by BIC on training rows.
std::optional<EffectFit> FitZeroDrift(const Context& cx, const Series& target) {
  const double duration = cx.data->t_s.back() - cx.data->t_s.front();
  // Per channel hat-spline fit with k intervals on every row_step-th training row.
  auto fit_k = [&](int k, int row_step, std::vector<Vec>* beta) {
    const HatBasis hb = MakeHat(cx, k);
    double sse_w = 0.0;
    beta->clear();
    for (int c = 0; c < cx.nc; ++c) {
      NormalEq ne(k + 1);
      for (int i = 0; i < cx.n; i += row_step) {
        if (!cx.train[static_cast<std::size_t>(i)]) continue;
        int j = 0;
        double fr = 0.0;
        hb.At(cx.data->t_s[static_cast<std::size_t>(i)], &j, &fr);
        const int idx[2] = {j, j + 1};
        const double val[2] = {1.0 - fr, fr};
        ne.AddSparse(idx, val, 2, target(i, c));
      }
      const auto r = ne.Solve();
      sse_w += r.sse * cx.weight(c) * row_step;
      beta->push_back(r.beta);
    }
    return sse_w;
  };
  double best_bic = std::numeric_limits<double>::infinity();
  int best_k = 0;
  std::vector<Vec> best_beta;
  double best_sse = 0.0;
  int worse = 0;
  for (int k : {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48}) {
    if (duration / k < 3.0 * cx.block_s) break;
    std::vector<Vec> beta;
    const double sse_w = fit_k(k, cx.search_stride, &beta);
    const double bic = sse_w + cx.nc * (k + 1) * Penalty(cx);
    if (bic < best_bic) {
      best_bic = bic;
      best_k = k;
      worse = 0;
    } else if (++worse >= 2) {
      break;
    }
  }
  if (best_k > 0) best_sse = fit_k(best_k, 1, &best_beta);
  if (best_k == 0) return std::nullopt;
  EffectFit best;
  best.name = "zero_drift";
  best.n_params = cx.nc * (best_k + 1);
  best.train_sse_w = best_sse;
  best.params["knots"] = best_k + 1;
  best.variant = Fmt("hat spline, %d knots", best_k + 1);
  best.pred.resize(cx.n, cx.nc);
  const HatBasis hb = MakeHat(cx, best_k);
  for (int i = 0; i < cx.n; ++i) {
    int j = 0;
    double fr = 0.0;
    hb.At(cx.data->t_s[static_cast<std::size_t>(i)], &j, &fr);
    for (int c = 0; c < cx.nc; ++c) {
      const Vec& bc = best_beta[static_cast<std::size_t>(c)];
      best.pred(i, c) = bc(j) * (1.0 - fr) + bc(j + 1) * fr;
    }
  }
  Vec span(cx.nc);
  for (int c = 0; c < cx.nc; ++c)
    span(c) = best.pred.col(c).maxCoeff() - best.pred.col(c).minCoeff();
  best.params["span_mvv"] = VecJson(span);
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  std::string temp_note;
  if (!cx.dtemp.empty()) {
    const double rt =
        Correlation(ColD(target, c).data(), cx.dtemp.data(), static_cast<std::size_t>(cx.n));
    temp_note = Fmt("; temperature explains less (r = %.2f)", rt);
  }
  best.evidence =
      Fmt("offset of b%d wanders by %.3g mV/V (%.1f σ) smoothly in time, r = %.2f with a %d-knot "
          "curve%s",
          c, span(c), span(c) / cx.sigma(c), RowCorr(cx, target, best.pred, c), best_k + 1,
          temp_note.c_str());
  return best;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ZeroDriftPlugin() {
  return {.kind = EffectKind::kZeroDrift,
          .traits = kTimeBased | kDriftInTime | kRefineOnlyIfBetter,
          .fit = &fx::FitZeroDrift,
          .refine_claim = &RefineWithThermalLag};
}

}  // namespace ftstack::diag
