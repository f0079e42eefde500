// geometric_nonlinearity: a cubic term of the load.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitGeometric(const Context& cx, const Series& target) {
  EffectFit e;
  e.name = "geometric_nonlinearity";
  Series pa;
  const auto fa = FitChannels(
      cx, target, 1,
      [&](int i, int c, double* x) {
        const double l = cx.load(i, c);
        x[0] = l * l * l;
      },
      &pa);
  double bic_b = std::numeric_limits<double>::infinity();
  Series pb;
  Vec kb;
  Vec kbs;
  if (cx.data->has_wrench()) {
    // Per-axis cubic softening/stiffening: r = Σ_k κ_k·S_·k·w_k³ (w normalised by its peak).
    Vec scale(6);
    for (int k = 0; k < 6; ++k)
      scale(k) = std::max<double>(cx.data->wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
    NormalEq ne(6);
    double x[6];
    for (int c = 0; c < cx.nc; ++c) {
      ForTrainingRows(cx, 0, cx.n, [&](int i) {
        for (int k = 0; k < 6; ++k) {
          const double u = cx.data->wrench(i, k) / scale(k);
          x[k] = cx.sens(c, k) * scale(k) * u * u * u;
        }
        ne.Add(x, target(i, c), cx.weight(c));
      });
    }
    const auto r = ne.Solve();
    kb = r.beta;
    kbs.resize(6);
    const double dof = std::max(1.0, static_cast<double>(cx.n_train * cx.nc) - 6.0);
    for (int k = 0; k < 6; ++k) kbs(k) = std::sqrt(r.cov_unit(k, k) * r.sse / dof);
    pb.resize(cx.n, cx.nc);
    for (int i = 0; i < cx.n; ++i) {
      for (int k = 0; k < 6; ++k) {
        const double u = cx.data->wrench(i, k) / scale(k);
        x[k] = scale(k) * u * u * u * kb(k);
      }
      for (int c = 0; c < cx.nc; ++c) {
        double v = 0.0;
        for (int k = 0; k < 6; ++k) v += cx.sens(c, k) * x[k];
        pb(i, c) = v;
      }
    }
    bic_b = r.sse + 6 * Penalty(cx);
  }
  const double bic_a = fa.sse_w + cx.nc * Penalty(cx);
  if (bic_a <= bic_b) {
    e.variant = "cubic in each bridge's output";
    e.pred = std::move(pa);
    e.n_params = cx.nc;
    e.train_sse_w = fa.sse_w;
    Vec g = fa.beta.row(0).transpose();
    const Vec gs = CoefSigmas(cx, fa, 0);
    e.params["cubic_per_mvv2"] = VecJson(g);
    e.sigma["cubic_per_mvv2"] = VecJson(gs);
  } else {
    e.variant = "cubic in each wrench component (relative at peak load)";
    e.pred = std::move(pb);
    e.n_params = 6;
    e.train_sse_w = bic_b - 6 * Penalty(cx);
    e.params["relative_at_peak"] = VecJson(kb);
    e.sigma["relative_at_peak"] = VecJson(kbs);
  }
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual of b%d is odd in load and grows with its cube (flat near zero, r = %.2f); %s",
          c, RowCorr(cx, target, e.pred, c), e.variant.c_str());
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec GeometricNonlinearityPlugin() {
  return {.kind = EffectKind::kGeometricNonlinearity, .fit = &fx::FitGeometric};
}

}  // namespace ftstack::diag
