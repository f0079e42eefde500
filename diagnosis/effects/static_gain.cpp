// Static effects of the load: gain_error, bridge_nonlinearity, geometric_nonlinearity,
// load_stiffening, misalignment.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {

// One coefficient per channel on a feature of the channel's load; significant channels only.
template <class F>
std::optional<EffectFit> SelectedChannelFit(const Context& cx, const Series& target, F feat,
                                            const char* name, const char* coef_name,
                                            std::vector<int>* chosen, ChannelFit* fit) {
  Series pred;
  const auto all = FitChannels(cx, target, 1, feat, &pred);
  std::vector<int> sel = SignificantChannels(cx, all, pred, 0);
  if (sel.empty()) {
    // Keep the single strongest channel so the candidate still exists (and will lose on hold-out).
    sel.push_back(DominantChannel(cx, pred));
  }
  EffectFit e;
  e.name = name;
  *fit = FitChannels(cx, target, 1, feat, &e.pred, &sel);
  e.train_sse_w = fit->sse_w;
  e.n_params = static_cast<int>(sel.size());
  e.channels = sel;
  auto coefs = nlohmann::json::array();
  auto sig = nlohmann::json::array();
  for (int c : sel) {
    coefs.push_back(fit->beta(0, c));
    sig.push_back(ParamSigma(cx, *fit, c, 0));
  }
  e.params["channels"] = IntList(sel);
  e.params[coef_name] = coefs;
  e.sigma[coef_name] = sig;
  *chosen = sel;
  return e;
}

std::optional<EffectFit> FitGainError(const Context& cx, const Series& target) {
  std::vector<int> sel;
  ChannelFit f;
  auto e = SelectedChannelFit(
      cx, target, [&](int i, int c, double* x) { x[0] = cx.load(i, c); }, "gain_error", "gain",
      &sel, &f);
  auto gains = nlohmann::json::array();
  for (int c : sel) gains.push_back(1.0 + f.beta(0, c));
  e->params["gain"] = gains;
  const int c = sel.front();
  e->evidence =
      Fmt("residual of %s is proportional to its own load output (r = %.2f): gain real/sim = %.5f, "
          "other channels unaffected",
          ChannelList(sel).c_str(), RowCorr(cx, target, e->pred, c), 1.0 + f.beta(0, c));
  return e;
}

std::optional<EffectFit> FitBridgeNonlinearity(const Context& cx, const Series& target) {
  std::vector<int> sel;
  ChannelFit f;
  auto e = SelectedChannelFit(
      cx, target,
      [&](int i, int c, double* x) {
        const double l = cx.load(i, c);
        x[0] = l * l;
      },
      "bridge_nonlinearity", "quadratic_per_mvv", &sel, &f);
  const int c = sel.front();
  e->evidence = Fmt(
      "residual of %s grows with the square of its output (same sign for + and − load), r = %.2f, "
      "%.3g mV/V at full scale",
      ChannelList(sel).c_str(), RowCorr(cx, target, e->pred, c),
      f.beta(0, c) * cx.load.col(c).cwiseAbs().maxCoeff() * cx.load.col(c).cwiseAbs().maxCoeff());
  return e;
}

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
      for (int i = 0; i < cx.n; ++i) {
        if (!cx.train[static_cast<std::size_t>(i)]) continue;
        for (int k = 0; k < 6; ++k) {
          const double u = cx.data->wrench(i, k) / scale(k);
          x[k] = cx.sens(c, k) * scale(k) * u * u * u;
        }
        ne.Add(x, target(i, c), cx.weight(c));
      }
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
    Vec gs(cx.nc);
    for (int c = 0; c < cx.nc; ++c) gs(c) = ParamSigma(cx, fa, c, 0);
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
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      const double fz = w(i, 2) / scale(2);
      for (int j = 0; j < 4; ++j) x[j] = fz * cx.sens(c, ks[j]) * w(i, ks[j]);
      ne.Add(x, target(i, c), cx.weight(c));
    }
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
      kappa[kWrenchNames[ks[j]]] = ra.beta(j);
      ksig[kWrenchNames[ks[j]]] = std::sqrt(ra.cov_unit(j, j) * ra.sse / dof);
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

std::optional<EffectFit> FitMisalignment(const Context& cx, const Series& target) {
  if (!cx.data->has_wrench()) return std::nullopt;
  const auto& w = cx.data->wrench;
  // Sensor frame rotated by +θ about an axis: it reads Rᵀ·F and Rᵀ·M, so the change of the wrench
  // is exactly (cos θ − 1)·U + sin θ·V with U, V linear in the wrench; the residual is S times
  // that.
  auto uv = [&](int axis, int i, Eigen::Matrix<double, 6, 1>* u, Eigen::Matrix<double, 6, 1>* v) {
    const int a1 = (axis + 1) % 3;
    const int a2 = (axis + 2) % 3;
    u->setZero();
    v->setZero();
    for (int off : {0, 3}) {
      (*u)(off + a1) = w(i, off + a1);
      (*u)(off + a2) = w(i, off + a2);
      (*v)(off + a1) = w(i, off + a2);
      (*v)(off + a2) = -w(i, off + a1);
    }
  };
  EffectFit best;
  double best_sse = std::numeric_limits<double>::infinity();
  const double lim = 20.0 * M_PI / 180.0;
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    double rr = 0, r1 = 0, r2 = 0, q11 = 0, q22 = 0, q12 = 0;
    Eigen::Matrix<double, 6, 1> u;
    Eigen::Matrix<double, 6, 1> v;
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      uv(axis, i, &u, &v);
      for (int c = 0; c < cx.nc; ++c) {
        const double p1 = cx.sens.row(c).dot(u);
        const double p2 = cx.sens.row(c).dot(v);
        const double r = target(i, c);
        const double wc = cx.weight(c);
        rr += wc * r * r;
        r1 += wc * r * p1;
        r2 += wc * r * p2;
        q11 += wc * p1 * p1;
        q22 += wc * p2 * p2;
        q12 += wc * p1 * p2;
      }
    }
    auto sse = [&](double th) {
      const double cm = std::cos(th) - 1.0;
      const double sn = std::sin(th);
      return rr - 2 * cm * r1 - 2 * sn * r2 + cm * cm * q11 + sn * sn * q22 + 2 * cm * sn * q12;
    };
    std::vector<double> grid;
    for (int j = -40; j <= 40; ++j) grid.push_back(lim * j / 40.0);
    double fmin = 0.0;
    const double th = MinimizeOnGrid(sse, grid, 40, &fmin);
    if (fmin < best_sse) {
      best_sse = fmin;
      EffectFit e;
      e.name = "misalignment";
      e.n_params = 1;
      e.train_sse_w = fmin;
      e.pred.resize(cx.n, cx.nc);
      const double cm = std::cos(th) - 1.0;
      const double sn = std::sin(th);
      for (int i = 0; i < cx.n; ++i) {
        uv(axis, i, &u, &v);
        const Eigen::Matrix<double, 6, 1> dw = cm * u + sn * v;
        for (int c = 0; c < cx.nc; ++c) e.pred(i, c) = cx.sens.row(c).dot(dw);
      }
      e.params["axis"] = names[axis];
      e.params["angle_deg"] = th * 180.0 / M_PI;
      e.sigma["angle_deg"] = JsonNum(CurvatureSigma(sse, th, 1e-5) * 180.0 / M_PI);
      best = std::move(e);
    }
  }
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  best.evidence =
      Fmt("cross-talk on %d channels is explained by one rotation of the sensor frame, %.2f° about "
          "%s (b%d r = %.2f)",
          static_cast<int>(best.channels.size()), best.params["angle_deg"].get<double>(),
          best.params["axis"].get<std::string>().c_str(), c, RowCorr(cx, target, best.pred, c));
  return best;
}

}  // namespace ftstack::diag::fx
