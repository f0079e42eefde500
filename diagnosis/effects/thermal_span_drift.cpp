// thermal_span_drift: the sensitivity changing with temperature (load × temperature change).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitThermalSpan(const Context& cx, const Series& target) {
  if (cx.dtemp.empty()) return std::nullopt;
  // Variant A: common coefficient, r = k·ΔT·L + γ·L; variant B: per channel.
  EffectFit e;
  e.name = "thermal_span_drift";
  NormalEq ne(2);
  for (int c = 0; c < cx.nc; ++c) {
    ForTrainingRows(cx, 0, cx.n, [&](int i) {
      const double l = cx.load(i, c);
      const double x[2] = {cx.dtemp[static_cast<std::size_t>(i)] * l, l};
      ne.Add(x, target(i, c), cx.weight(c));
    });
  }
  const auto rc = ne.Solve();
  Series pa(cx.n, cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      pa(i, c) = (rc.beta(0) * cx.dtemp[static_cast<std::size_t>(i)] + rc.beta(1)) * cx.load(i, c);
    }
  }
  const double dof = std::max(1.0, static_cast<double>(cx.n_train * cx.nc) - 2.0);
  const double ka_sigma = std::sqrt(rc.cov_unit(0, 0) * rc.sse / dof);
  Series pb;
  const auto fb = FitChannels(
      cx, target, 2,
      [&](int i, int c, double* x) {
        x[0] = cx.dtemp[static_cast<std::size_t>(i)] * cx.load(i, c);
        x[1] = cx.load(i, c);
      },
      &pb);
  const double bic_a = rc.sse + 2 * Penalty(cx);
  const double bic_b = fb.sse_w + 2 * cx.nc * Penalty(cx);
  Vec kb = fb.beta.row(0).transpose();
  const Vec kbs = CoefSigmas(cx, fb, 0);
  if (bic_a <= bic_b) {
    e.variant = "common coefficient";
    e.pred = std::move(pa);
    e.n_params = 2;
    e.train_sse_w = rc.sse;
    e.params["coef_per_K"] = rc.beta(0);
    e.sigma["coef_per_K"] = ka_sigma;
    e.params["ref_temp_C"] = rc.beta(0) != 0 ? 20.0 - rc.beta(1) / rc.beta(0) : 20.0;
  } else {
    e.variant = "per-channel coefficients";
    e.pred = std::move(pb);
    e.n_params = 2 * cx.nc;
    e.train_sse_w = fb.sse_w;
    // Energy-weighted mean as the headline number.
    double num = 0.0;
    double den = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      const double wgt = cx.load.col(c).squaredNorm() * cx.weight(c);
      num += wgt * kb(c);
      den += wgt;
    }
    e.params["coef_per_K"] = den > 0 ? num / den : 0.0;
    e.params["coef_per_K_by_channel"] = VecJson(kb);
    e.sigma["coef_per_K_by_channel"] = VecJson(kbs);
  }
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual of b%d grows with load × temperature change, r = %.2f; sensitivity changes "
          "%+.3g %%/K",
          c, RowCorr(cx, target, e.pred, c), 100.0 * e.params["coef_per_K"].get<double>());
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ThermalSpanDriftPlugin() {
  return {.kind = EffectKind::kThermalSpanDrift,
          .traits = kTimeBased | kNeedsTemperature,
          .confounders = kConfoundersOfTime | kTimeDrift,
          .fit = &fx::FitThermalSpan};
}

}  // namespace ftstack::diag
