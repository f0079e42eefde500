// load_stiffening: the bending and shear sensitivities changing with the axial force.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitLoadStiffening(const Context& cx, const Series& target) {
  if (!cx.data->has_wrench()) return std::nullopt;
  const auto& w = cx.data->wrench;
  const int ks[4] = {0, 1, 3, 4};
  Vec scale(6);
  for (int k = 0; k < 6; ++k) scale(k) = std::max<double>(w.col(k).cwiseAbs().maxCoeff(), 1e-12);
  // Variant A: physically structured, the sensitivity to w_k scales by (1 + κ_k·Fz/Fz_peak).
  NormalEq ne(4);
  double x[4];
  for (int c = 0; c < cx.nc; ++c) {
    ForTrainingRows(cx, 0, cx.n, [&](int i) {
      const double fz = w(i, 2) / scale(2);
      for (int j = 0; j < 4; ++j) x[j] = fz * cx.sens(c, ks[j]) * w(i, ks[j]);
      ne.Add(x, target(i, c), cx.weight(c));
    });
  }
  const auto ra = ne.Solve();
  // Variant B: free coefficients of Fz·w_k per channel.
  Series pb;
  const auto fb = FitChannels(
      cx, target, 4,
      [&](int i, int, double* xx) {
        const double fz = w(i, 2) / scale(2);
        for (int j = 0; j < 4; ++j) xx[j] = fz * w(i, ks[j]) / scale(ks[j]);
      },
      &pb);
  const double bic_a = ra.sse + 4 * Penalty(cx);
  const double bic_b = fb.sse_w + 4 * cx.nc * Penalty(cx);
  EffectFit e;
  e.name = "load_stiffening";
  if (bic_a <= bic_b) {
    e.variant = "sensitivity to Fx, Fy, Mx, My scaled by (1 + κ·Fz/Fz_peak)";
    e.n_params = 4;
    e.train_sse_w = ra.sse;
    e.pred.resize(cx.n, cx.nc);
    for (int i = 0; i < cx.n; ++i) {
      const double fz = w(i, 2) / scale(2);
      for (int c = 0; c < cx.nc; ++c) {
        double v = 0.0;
        for (int j = 0; j < 4; ++j) v += ra.beta(j) * fz * cx.sens(c, ks[j]) * w(i, ks[j]);
        e.pred(i, c) = v;
      }
    }
    auto kappa = nlohmann::json::object();
    auto ksig = nlohmann::json::object();
    const double dof = std::max(1.0, static_cast<double>(cx.n_train * cx.nc) - 4.0);
    for (int j = 0; j < 4; ++j) {
      kappa[kWrenchAxisNames[ks[j]]] = ra.beta(j);
      ksig[kWrenchAxisNames[ks[j]]] = std::sqrt(ra.cov_unit(j, j) * ra.sse / dof);
    }
    e.params["kappa_at_peak_Fz"] = kappa;
    e.sigma["kappa_at_peak_Fz"] = ksig;
  } else {
    e.variant = "free Fz·(Fx, Fy, Mx, My) terms per channel";
    e.n_params = 4 * cx.nc;
    e.train_sse_w = fb.sse_w;
    e.pred = std::move(pb);
    e.params["terms"] = "Fz*Fx, Fz*Fy, Fz*Mx, Fz*My";
  }
  e.params["fz_peak_n"] = scale(2);
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual of b%d appears only when axial load and bending/shear load act together (Fz·w "
          "terms, r = %.2f)",
          c, RowCorr(cx, target, e.pred, c));
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec LoadStiffeningPlugin() {
  return {.kind = EffectKind::kLoadStiffening, .fit = &fx::FitLoadStiffening};
}

}  // namespace ftstack::diag
