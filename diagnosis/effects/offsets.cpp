// Offset and drift effects: zero_offset, zero_drift, thermal_zero_drift (no lag),
// thermal_span_drift, excitation_drift.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitZeroOffset(const Context& cx, const Series& target) {
  EffectFit e;
  e.name = "zero_offset";
  const auto f = FitChannels(
      cx, target, 1, [](int, int, double* x) { x[0] = 1.0; }, &e.pred);
  e.n_params = cx.nc;
  const Vec off = PutChannelCoef(cx, f, 0, "offset", &e);
  e.train_sse_w = f.sse_w;
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual is a constant %+.3g mV/V (%.1f noise σ) on b%d, the same in every time block",
          off(c), std::fabs(off(c)) / cx.sigma(c), c);
  return e;
}

// Smooth functions of time per channel (hat splines), knots chosen by BIC on training rows.
std::optional<EffectFit> FitZeroDrift(const Context& cx, const Series& target) {
  const double duration = cx.data->t_s.back() - cx.data->t_s.front();
  // Per channel hat-spline fit with k intervals on every st-th training row.
  auto fit_k = [&](int k, int st, std::vector<Vec>* beta) {
    const HatBasis hb = MakeHat(cx, k);
    double sse_w = 0.0;
    beta->clear();
    for (int c = 0; c < cx.nc; ++c) {
      NormalEq ne(k + 1);
      for (int i = 0; i < cx.n; i += st) {
        if (!cx.train[static_cast<std::size_t>(i)]) continue;
        int j = 0;
        double fr = 0.0;
        hb.At(cx.data->t_s[static_cast<std::size_t>(i)], &j, &fr);
        const int idx[2] = {j, j + 1};
        const double val[2] = {1.0 - fr, fr};
        ne.AddSparse(idx, val, 2, target(i, c));
      }
      const auto r = ne.Solve();
      sse_w += r.sse * cx.weight(c) * st;
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

std::optional<EffectFit> FitThermalSpan(const Context& cx, const Series& target) {
  if (cx.dtemp.empty()) return std::nullopt;
  // Variant A: common coefficient, r = k·ΔT·L + γ·L; variant B: per channel.
  EffectFit e;
  e.name = "thermal_span_drift";
  NormalEq ne(2);
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      const double l = cx.load(i, c);
      const double x[2] = {cx.dtemp[static_cast<std::size_t>(i)] * l, l};
      ne.Add(x, target(i, c), cx.weight(c));
    }
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
  Vec kbs(cx.nc);
  for (int c = 0; c < cx.nc; ++c) kbs(c) = ParamSigma(cx, fb, c, 0);
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
      for (int i = 0; i < cx.n; ++i) {
        if (!cx.train[static_cast<std::size_t>(i)]) continue;
        const int j = hat_j[static_cast<std::size_t>(i)];
        const double fr = hat_fr[static_cast<std::size_t>(i)];
        const double s = cx.sim_mvv(i, c);
        const int idx[2] = {j, j + 1};
        const double val[2] = {(1.0 - fr) * s, fr * s};
        ne.AddSparse(idx, val, 2, target(i, c), cx.weight(c));
      }
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
  return ExcitationSearch(
      cx, target,
      std::vector<int>(std::begin(kExcitationIntervals), std::end(kExcitationIntervals)));
}

std::optional<EffectFit> RefitExcitation(const Context& cx, const Series& target,
                                         const EffectFit& near, bool /*uncertainty*/) {
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

std::optional<EffectFit> FitThermalZeroPlain(const Context& cx, const Series& target) {
  return FitThermalZeroOn(cx, target, cx.dtemp);
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

std::optional<EffectFit> FitThermalZeroOn(const Context& cx, const Series& target,
                                          const std::vector<double>& dtemp) {
  if (dtemp.empty()) return std::nullopt;
  EffectFit e;
  e.name = "thermal_zero_drift";
  const auto f = FitChannels(
      cx, target, 2,
      [&](int i, int, double* x) {
        x[0] = 1.0;
        x[1] = dtemp[static_cast<std::size_t>(i)];
      },
      &e.pred);
  e.n_params = 2 * cx.nc;
  const Vec k = PutChannelCoef(cx, f, 1, "coef_per_K", &e);
  e.train_sse_w = f.sse_w;
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  // Compare with a straight line in time (same parameter count).
  Series lin;
  FitChannels(
      cx, target, 2,
      [&](int i, int, double* x) {
        x[0] = 1.0;
        x[1] = cx.data->t_s[static_cast<std::size_t>(i)];
      },
      &lin);
  e.evidence = Fmt(
      "residual of b%d follows temperature, r = %.2f (a line in time: r = %.2f), %+.3g mV/V per K",
      c, RowCorr(cx, target, e.pred, c), RowCorr(cx, target, lin, c), k(c));
  return e;
}

}  // namespace ftstack::diag
