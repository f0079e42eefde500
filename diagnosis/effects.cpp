#include "diagnosis/effects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

#include "diagnosis/signal.hpp"

namespace ftstack::diag {
namespace {

constexpr const char* kWrenchNames[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};

std::string Fmt(const char* f, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

double Ln(double x) { return std::log(std::max(x, 1.0)); }

/// BIC-like penalty per parameter for hyper-parameter choices on training data.
double Penalty(const Context& cx) { return Ln(static_cast<double>(cx.n_train) * cx.nc); }

struct ChannelFit {
  Mat beta;              // p × N
  std::vector<Mat> cov;  // per channel, unit
  Vec sse;               // per channel, unweighted
  double sse_w = 0.0;
};

/// Per-channel least squares target_c ≈ Σ_j beta_jc · feat(i, c)_j on training rows; fills pred.
template <class F>
ChannelFit FitChannels(const Context& cx, const Mat& target, int p, F feat, Mat* pred,
                       const std::vector<int>* only = nullptr, int stride = 1) {
  ChannelFit out;
  out.beta = Mat::Zero(p, cx.nc);
  out.cov.assign(static_cast<std::size_t>(cx.nc), Mat::Zero(p, p));
  out.sse = Vec::Zero(cx.nc);
  std::vector<double> x(static_cast<std::size_t>(p));
  if (pred != nullptr) pred->setZero(cx.n, cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    const bool active = only == nullptr || std::find(only->begin(), only->end(), c) != only->end();
    if (!active) {
      if (stride > 1) continue;  // searches only compare the active channels
      double s = 0.0;
      for (int i = 0; i < cx.n; ++i) {
        if (cx.train[static_cast<std::size_t>(i)]) s += target(i, c) * target(i, c);
      }
      out.sse(c) = s;
      out.sse_w += s * cx.weight(c);
      continue;
    }
    NormalEq ne(p);
    for (int i = 0; i < cx.n; i += stride) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      feat(i, c, x.data());
      ne.Add(x.data(), target(i, c));
    }
    const auto r = ne.Solve();
    out.beta.col(c) = r.beta;
    out.cov[static_cast<std::size_t>(c)] = r.cov_unit;
    out.sse(c) = r.sse;
    out.sse_w += r.sse * cx.weight(c);
    if (pred != nullptr) {
      for (int i = 0; i < cx.n; ++i) {
        feat(i, c, x.data());
        double v = 0.0;
        for (int j = 0; j < p; ++j) v += r.beta(j) * x[static_cast<std::size_t>(j)];
        (*pred)(i, c) = v;
      }
    }
  }
  return out;
}

/// σ of parameter j of channel c from its unit covariance and the channel's residual variance.
double ParamSigma(const Context& cx, const ChannelFit& f, int c, int j) {
  const double dof =
      std::max(1.0, static_cast<double>(cx.n_train) - static_cast<double>(f.beta.rows()));
  return std::sqrt(std::max(0.0, f.cov[static_cast<std::size_t>(c)](j, j) * f.sse(c) / dof));
}

/// Uncertainty of a nonlinear parameter from the curvature of the profile SSE (whitened, so
/// Δχ² = 1 at one σ): σ = sqrt(2 / f'').
double CurvatureSigma(const std::function<double(double)>& f, double x, double h) {
  const double f0 = f(x);
  const double fp = f(x + h);
  const double fm = f(x - h);
  const double d2 = (fp - 2.0 * f0 + fm) / (h * h);
  return d2 > 0 ? std::sqrt(2.0 / d2) : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json JsonNum(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json VecJson(const Vec& v) {
  auto a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(JsonNum(v(i)));
  return a;
}

/// Puts coefficient j of every channel and its σ into e.params[key] / e.sigma[key]; returns it.
Vec PutChannelCoef(const Context& cx, const ChannelFit& f, int j, const char* key, EffectFit* e) {
  Vec v = f.beta.row(j).transpose();
  Vec sg(cx.nc);
  for (int c = 0; c < cx.nc; ++c) sg(c) = ParamSigma(cx, f, c, j);
  e->params[key] = VecJson(v);
  e->sigma[key] = VecJson(sg);
  return v;
}

/// Whitened training SSE of a one-coefficient-per-channel fit of `feature` (n × N), on every
/// search_stride-th row and scaled back to the full count: the objective of parameter searches.
double SearchSse(const Context& cx, const Mat& target, const Mat& feature) {
  const int st = cx.search_stride;
  return FitChannels(
             cx, target, 1, [&](int i, int c, double* x) { x[0] = feature(i, c); }, nullptr,
             nullptr, st)
             .sse_w *
         st;
}

/// Channel whose prediction carries the largest whitened energy.
int DominantChannel(const Context& cx, const Mat& pred) {
  int best = 0;
  double be = -1.0;
  for (int c = 0; c < cx.nc; ++c) {
    const double e = pred.col(c).squaredNorm() * cx.weight(c);
    if (e > be) {
      be = e;
      best = c;
    }
  }
  return best;
}

/// Channels carrying at least `share` of the prediction's whitened energy.
std::vector<int> ActiveChannels(const Context& cx, const Mat& pred, double share = 0.02) {
  Vec e(cx.nc);
  for (int c = 0; c < cx.nc; ++c) e(c) = pred.col(c).squaredNorm() * cx.weight(c);
  std::vector<int> out;
  const double tot = e.sum();
  for (int c = 0; c < cx.nc; ++c) {
    if (tot > 0 && e(c) >= share * tot) out.push_back(c);
  }
  return out;
}

/// Channels whose single coefficient is significant (|β|/σ > 5) and carries ≥ 5 % of the energy
/// explained across channels.
std::vector<int> SignificantChannels(const Context& cx, const ChannelFit& f, const Mat& pred,
                                     int j) {
  std::vector<int> out;
  Vec e(cx.nc);
  for (int c = 0; c < cx.nc; ++c) e(c) = pred.col(c).squaredNorm() * cx.weight(c);
  const double tot = e.sum();
  for (int c = 0; c < cx.nc; ++c) {
    const double s = ParamSigma(cx, f, c, j);
    if (s > 0 && std::fabs(f.beta(j, c)) > 5.0 * s && e(c) >= 0.05 * tot) out.push_back(c);
  }
  return out;
}

std::string ChannelList(const std::vector<int>& ch) {
  std::string s;
  for (std::size_t i = 0; i < ch.size(); ++i) {
    if (i) s += ", ";
    s += "b" + std::to_string(ch[i]);
  }
  return s;
}

nlohmann::json IntList(const std::vector<int>& ch) {
  auto a = nlohmann::json::array();
  for (int c : ch) a.push_back(c);
  return a;
}

double RowCorr(const Context& cx, const Mat& target, const Mat& pred, int c) {
  return Correlation(target.col(c).data(), pred.col(c).data(), static_cast<std::size_t>(cx.n));
}

// Hat (linear B-spline) basis in time with k intervals: row i → (index, fraction).
struct HatBasis {
  double t0 = 0.0;
  double h = 1.0;
  int k = 1;
  void At(double t, int* idx, double* frac) const {
    double u = (t - t0) / h;
    int j = static_cast<int>(std::floor(u));
    if (j < 0) j = 0;
    if (j >= k) j = k - 1;
    *idx = j;
    *frac = std::clamp(u - j, 0.0, 1.0);
  }
};

HatBasis MakeHat(const Context& cx, int k) {
  HatBasis b;
  b.t0 = cx.data->t_s.front();
  b.k = k;
  b.h = (cx.data->t_s.back() - b.t0) / k;
  return b;
}

// ---------------------------------------------------------------------------------------------
std::optional<EffectFit> FitZeroOffset(const Context& cx, const Mat& target) {
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
std::optional<EffectFit> FitZeroDrift(const Context& cx, const Mat& target) {
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
        Correlation(target.col(c).data(), cx.dtemp.data(), static_cast<std::size_t>(cx.n));
    temp_note = Fmt("; temperature explains less (r = %.2f)", rt);
  }
  best.evidence =
      Fmt("offset of b%d wanders by %.3g mV/V (%.1f σ) smoothly in time, r = %.2f with a %d-knot "
          "curve%s",
          c, span(c), span(c) / cx.sigma(c), RowCorr(cx, target, best.pred, c), best_k + 1,
          temp_note.c_str());
  return best;
}

std::optional<EffectFit> FitThermalZeroPlain(const Context& cx, const Mat& target);

}  // namespace

std::optional<EffectFit> FitThermalZeroOn(const Context& cx, const Mat& target,
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
  Mat lin;
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

namespace {

std::optional<EffectFit> FitThermalSpan(const Context& cx, const Mat& target) {
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
  Mat pa(cx.n, cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      pa(i, c) = (rc.beta(0) * cx.dtemp[static_cast<std::size_t>(i)] + rc.beta(1)) * cx.load(i, c);
    }
  }
  const double dof = std::max(1.0, static_cast<double>(cx.n_train * cx.nc) - 2.0);
  const double ka_sigma = std::sqrt(rc.cov_unit(0, 0) * rc.sse / dof);
  Mat pb;
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

std::optional<EffectFit> FitExcitation(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  const double duration = d.t_s.back() - d.t_s.front();
  double best_bic = std::numeric_limits<double>::infinity();
  EffectFit best;
  int worse = 0;
  for (int k : {1, 2, 3, 4, 6, 8, 12, 16, 24, 32}) {
    if (duration / k < 3.0 * cx.block_s) break;
    const HatBasis hb = MakeHat(cx, k);
    NormalEq ne(k + 1);
    for (int c = 0; c < cx.nc; ++c) {
      for (int i = 0; i < cx.n; ++i) {
        if (!cx.train[static_cast<std::size_t>(i)]) continue;
        int j = 0;
        double fr = 0.0;
        hb.At(d.t_s[static_cast<std::size_t>(i)], &j, &fr);
        const double s = d.sim_mvv(i, c);
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
      e.pred.resize(cx.n, cx.nc);
      Vec factor(cx.n);
      for (int i = 0; i < cx.n; ++i) {
        int j = 0;
        double fr = 0.0;
        hb.At(d.t_s[static_cast<std::size_t>(i)], &j, &fr);
        factor(i) = r.beta(j) * (1.0 - fr) + r.beta(j + 1) * fr;
        for (int c = 0; c < cx.nc; ++c) e.pred(i, c) = factor(i) * d.sim_mvv(i, c);
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

/// Restart flags of the context's segments for the filters (nullptr for one recording).
const std::uint8_t* Restarts(const Context& cx) {
  return cx.restart.empty() ? nullptr : cx.restart.data();
}

// Creep: r_c = β_c·LP_τ[L_c] (+ γ_c·L_c in the second variant).
std::optional<EffectFit> FitCreep(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  const double duration = d.t_s.back() - d.t_s.front();
  Mat lp(cx.n, cx.nc);
  std::vector<const double*> in_cols;
  std::vector<double*> out_cols;
  for (int c = 0; c < cx.nc; ++c) {
    in_cols.push_back(cx.load.col(c).data());
    out_cols.push_back(lp.col(c).data());
  }
  auto build = [&](double tau) {
    FirstOrderLowPassColumns(d.t_s.data(), static_cast<std::size_t>(cx.n), tau, in_cols.data(),
                             out_cols.data(), in_cols.size(), Restarts(cx));
  };
  auto sse_for = [&](double log_tau, bool gamma) {
    build(std::exp(log_tau));
    const int st = cx.search_stride;
    if (gamma) {
      return FitChannels(
                 cx, target, 2,
                 [&](int i, int c, double* x) {
                   x[0] = lp(i, c);
                   x[1] = cx.load(i, c);
                 },
                 nullptr, nullptr, st)
                 .sse_w *
             st;
    }
    return SearchSse(cx, target, lp);
  };
  std::vector<double> grid;
  const double lo = std::log(std::max(3.0 * cx.dt, 0.2));
  const double hi = std::log(std::max(duration, 1.0));
  for (int j = 0; j <= 12; ++j) grid.push_back(lo + (hi - lo) * j / 12.0);
  EffectFit best;
  double best_bic = std::numeric_limits<double>::infinity();
  // τ is searched with the plain model; the variant with a gain term reuses it.
  const double lt = MinimizeOnGrid([&](double v) { return sse_for(v, false); }, grid, 12, nullptr);
  for (bool gamma : {false, true}) {
    const int p = cx.nc * (gamma ? 2 : 1) + 1;
    EffectFit e;
    e.name = "creep";
    e.variant = gamma ? "first-order creep with a gain term" : "first-order creep";
    e.n_params = p;
    const double tau = std::exp(lt);
    const double sl = CurvatureSigma([&](double v) { return sse_for(v, gamma); }, lt, 0.02);
    build(tau);
    ChannelFit f;
    if (gamma) {
      f = FitChannels(
          cx, target, 2,
          [&](int i, int c, double* x) {
            x[0] = lp(i, c);
            x[1] = cx.load(i, c);
          },
          &e.pred);
    } else {
      f = FitChannels(
          cx, target, 1, [&](int i, int c, double* x) { x[0] = lp(i, c); }, &e.pred);
    }
    e.train_sse_w = f.sse_w;
    const double bic = f.sse_w + p * Penalty(cx);
    if (bic >= best_bic) continue;
    best_bic = bic;
    e.params["tau_s"] = tau;
    e.sigma["tau_s"] = JsonNum(tau * sl);
    PutChannelCoef(cx, f, 0, "fraction", &e);
    best = std::move(e);
  }
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  best.evidence =
      Fmt("during load holds b%d keeps moving toward a new value with τ = %.1f s (%.2f %% of the "
          "load) and recovers after unloading, r = %.2f",
          c, best.params["tau_s"].get<double>(),
          100.0 * best.params["fraction"][static_cast<std::size_t>(c)].get<double>(),
          RowCorr(cx, target, best.pred, c));
  return best;
}

}  // namespace

std::optional<EffectFit> FitHysteresisOperator(const Context& cx, const Mat& target) {
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
  std::vector<double> grid;
  for (int j = 0; j <= 10; ++j)
    grid.push_back(std::log(0.002) + (std::log(2.0) - std::log(0.002)) * j / 10.0);
  EffectFit best;
  for (bool play : {false, true}) {
    auto f1 = [&](double v) { return sse_for(v, play); };
    const double lw = MinimizeOnGrid(f1, grid, 10, nullptr);
    EffectFit e;
    e.name = "hysteresis";
    e.variant = play ? "rate-independent play (backlash) operator on each bridge's load"
                     : "rate-independent Dahl operator on each bridge's load";
    e.n_params = cx.nc + 1;
    const double sl = CurvatureSigma(f1, lw, 0.02);
    build(lw, play);
    const auto f = FitChannels(
        cx, target, 1, [&](int i, int c, double* x) { x[0] = z(i, c); }, &e.pred);
    e.train_sse_w = f.sse_w;
    if (!best.name.empty() && best.train_sse_w <= e.train_sse_w) continue;
    PutChannelCoef(cx, f, 0, "half_width_mvv", &e);
    e.params["travel_fraction"] = std::exp(lw);
    e.sigma["travel_fraction"] = JsonNum(std::exp(lw) * sl);
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

namespace {

// One coefficient per channel on a feature of the channel's load; significant channels only.
template <class F>
std::optional<EffectFit> SelectedChannelFit(const Context& cx, const Mat& target, F feat,
                                            const char* name, const char* coef_name,
                                            std::vector<int>* chosen, ChannelFit* fit) {
  Mat pred;
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

std::optional<EffectFit> FitGainError(const Context& cx, const Mat& target) {
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

std::optional<EffectFit> FitBridgeNonlinearity(const Context& cx, const Mat& target) {
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

std::optional<EffectFit> FitGeometric(const Context& cx, const Mat& target) {
  EffectFit e;
  e.name = "geometric_nonlinearity";
  Mat pa;
  const auto fa = FitChannels(
      cx, target, 1,
      [&](int i, int c, double* x) {
        const double l = cx.load(i, c);
        x[0] = l * l * l;
      },
      &pa);
  double bic_b = std::numeric_limits<double>::infinity();
  Mat pb;
  Vec kb;
  Vec kbs;
  if (cx.data->has_wrench()) {
    // Per-axis cubic softening/stiffening: r = Σ_k κ_k·S_·k·w_k³ (w normalised by its peak).
    Vec scale(6);
    for (int k = 0; k < 6; ++k)
      scale(k) = std::max(cx.data->wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
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

std::optional<EffectFit> FitLoadStiffening(const Context& cx, const Mat& target) {
  if (!cx.data->has_wrench()) return std::nullopt;
  const auto& w = cx.data->wrench;
  const int ks[4] = {0, 1, 3, 4};
  Vec scale(6);
  for (int k = 0; k < 6; ++k) scale(k) = std::max(w.col(k).cwiseAbs().maxCoeff(), 1e-12);
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
  Mat pb;
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

std::optional<EffectFit> FitMisalignment(const Context& cx, const Mat& target) {
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

std::optional<EffectFit> FitTimeSkew(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  auto predict = [&](double delay, Mat* out) {
    double sse = 0.0;
    const int st = out == nullptr ? cx.search_stride : 1;
    for (int c = 0; c < cx.nc; ++c) {
      const double* s = d.sim_mvv.col(c).data();
      double acc = 0.0;
      for (int i = 0; i < cx.n; i += st) {
        const bool tr = cx.train[static_cast<std::size_t>(i)] != 0;
        if (!tr && out == nullptr) continue;
        const double v = InterpolateAt(d.t_s.data(), s, static_cast<std::size_t>(cx.n),
                                       d.t_s[static_cast<std::size_t>(i)] - delay, cx.uniform) -
                         s[i];
        if (out != nullptr) (*out)(i, c) = v;
        if (tr) acc += (target(i, c) - v) * (target(i, c) - v);
      }
      sse += acc * cx.weight(c) * st;
    }
    return sse;
  };
  // Linear estimate r ≈ −delay·ds/dt.
  double num = 0.0;
  double den = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 1; i + 1 < cx.n; ++i) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      const double ds =
          (d.sim_mvv(i + 1, c) - d.sim_mvv(i - 1, c)) /
          (d.t_s[static_cast<std::size_t>(i + 1)] - d.t_s[static_cast<std::size_t>(i - 1)]);
      num += -target(i, c) * ds * cx.weight(c);
      den += ds * ds * cx.weight(c);
    }
  }
  if (den <= 0) return std::nullopt;
  const double d0 = num / den;
  const double span = std::max(2.0 * cx.dt, std::fabs(d0));
  std::vector<double> grid;
  for (int j = -6; j <= 6; ++j) grid.push_back(d0 + span * j / 6.0);
  double fmin = 0.0;
  auto f = [&](double v) { return predict(v, nullptr); };
  const double delay = MinimizeOnGrid(f, grid, 16, &fmin);
  EffectFit e;
  e.name = "time_skew";
  e.n_params = 1;
  e.pred.resize(cx.n, cx.nc);
  e.train_sse_w = predict(delay, &e.pred);
  e.params["delay_s"] = delay;
  e.sigma["delay_s"] = JsonNum(CurvatureSigma(f, delay, 0.02 * cx.dt));
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual of b%d is −delay × d(sim)/dt, largest on fast ramps and zero on holds: real %s "
          "by %.3g ms (%.2f samples), r = %.2f",
          c, delay >= 0 ? "lags" : "leads", std::fabs(delay) * 1e3, std::fabs(delay) / cx.dt,
          RowCorr(cx, target, e.pred, c));
  return e;
}

std::optional<EffectFit> FitSaturation(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  // Real = sim + residual; a clipping limit shows up as the extremes of the real outputs.
  double hi = -std::numeric_limits<double>::infinity();
  double lo = std::numeric_limits<double>::infinity();
  double sim_hi = hi;
  double sim_lo = lo;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      const double s = d.sim_mvv(i, c);
      const double r = s + target(i, c);
      hi = std::max(hi, r);
      lo = std::min(lo, r);
      sim_hi = std::max(sim_hi, s);
      sim_lo = std::min(sim_lo, s);
    }
  }
  // Clipping needs the sim to go beyond what the real file ever reads.
  if (sim_hi <= hi && sim_lo >= lo) return std::nullopt;
  auto predict = [&](double l, double h, Mat* out) {
    double sse = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      double acc = 0.0;
      for (int i = 0; i < cx.n; ++i) {
        const double s = d.sim_mvv(i, c);
        const double v = std::clamp(s, l, h) - s;
        if (out != nullptr) (*out)(i, c) = v;
        if (cx.train[static_cast<std::size_t>(i)]) acc += (target(i, c) - v) * (target(i, c) - v);
      }
      sse += acc * cx.weight(c);
    }
    return sse;
  };
  const double range = std::max(sim_hi - sim_lo, 1e-9);
  auto refine = [&](double start, bool upper, double other) {
    std::vector<double> grid;
    for (int j = -4; j <= 4; ++j) grid.push_back(start + 0.01 * range * j);
    return MinimizeOnGrid(
        [&](double v) { return upper ? predict(other, v, nullptr) : predict(v, other, nullptr); },
        grid, 12, nullptr);
  };
  const double h1 = refine(hi, true, -std::numeric_limits<double>::infinity());
  const double l1 = refine(lo, false, h1);
  const double lim = std::max(std::fabs(lo), std::fabs(hi));
  EffectFit e;
  e.name = "saturation";
  e.pred.resize(cx.n, cx.nc);
  const double sse_sym = predict(-lim, lim, nullptr);
  const double sse_asym = predict(l1, h1, nullptr);
  if (sse_sym + Penalty(cx) <= sse_asym + 2 * Penalty(cx)) {
    e.variant = "symmetric limit";
    e.n_params = 1;
    e.train_sse_w = predict(-lim, lim, &e.pred);
    e.params["limit"] = lim;
  } else {
    e.variant = "asymmetric limits";
    e.n_params = 2;
    e.train_sse_w = predict(l1, h1, &e.pred);
    e.params["limit"] = std::max(std::fabs(l1), std::fabs(h1));
    e.params["limit_low"] = l1;
    e.params["limit_high"] = h1;
  }
  e.sigma["limit"] = cx.sigma.maxCoeff() / 2.0;
  e.channels = ActiveChannels(cx, e.pred);
  int pinned = 0;
  const double l = e.params["limit"].get<double>();
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (std::fabs(d.sim_mvv(i, c)) > l) ++pinned;
    }
  }
  e.evidence = Fmt(
      "%d samples where the sim exceeds %.4g mV/V read back pinned at the limit (sim reaches %.4g)",
      pinned, l, std::max(std::fabs(sim_lo), std::fabs(sim_hi)));
  return e;
}

std::optional<EffectFit> FitOverloadShift(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  std::vector<int> rows;
  for (int i = 0; i < cx.n; ++i) {
    if (cx.train[static_cast<std::size_t>(i)]) rows.push_back(i);
  }
  const auto m = rows.size();
  if (m < 40) return std::nullopt;
  // Suffix sums per channel: a step from 0 to a_c after the split explains Σ_c w_c·S_c²/n_after.
  Mat suffix = Mat::Zero(static_cast<Eigen::Index>(m + 1), cx.nc);
  for (std::size_t j = m; j-- > 0;) {
    for (int c = 0; c < cx.nc; ++c)
      suffix(static_cast<Eigen::Index>(j), c) =
          suffix(static_cast<Eigen::Index>(j + 1), c) + target(rows[j], c);
  }
  double best = -1.0;
  std::size_t bj = 0;
  for (std::size_t j = 10; j + 10 < m; ++j) {
    const double na = static_cast<double>(m - j);
    double g = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      const double s = suffix(static_cast<Eigen::Index>(j), c);
      g += cx.weight(c) * s * s / na;
    }
    if (g > best) {
      best = g;
      bj = j;
    }
  }
  const double t_after = d.t_s[static_cast<std::size_t>(rows[bj])];
  const double t_before = d.t_s[static_cast<std::size_t>(rows[bj - 1])];
  const double onset = rows[bj] - rows[bj - 1] > 1 ? 0.5 * (t_before + t_after) : t_after;
  EffectFit e;
  e.name = "overload_shift";
  e.n_params = cx.nc + 1;
  const auto f = FitChannels(
      cx, target, 1,
      [&](int i, int, double* x) {
        x[0] = d.t_s[static_cast<std::size_t>(i)] >= onset ? 1.0 : 0.0;
      },
      &e.pred);
  e.train_sse_w = f.sse_w;
  const Vec a = PutChannelCoef(cx, f, 0, "shift", &e);
  e.params["onset_s"] = onset;
  e.sigma["onset_s"] = std::max(cx.dt, (t_after - t_before) / std::sqrt(12.0));
  e.channels = ActiveChannels(cx, e.pred);
  // The load peak nearest before the onset (an overload is the physical cause).
  std::string load_note;
  if (d.has_wrench()) {
    double peak = 0.0;
    int pk = 0;
    int pi = 0;
    double scale[6];
    for (int k = 0; k < 6; ++k) scale[k] = std::max(d.wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
    for (int i = 0; i < cx.n && d.t_s[static_cast<std::size_t>(i)] <= onset + 2.0 * cx.block_s;
         ++i) {
      for (int k = 0; k < 6; ++k) {
        const double v = std::fabs(d.wrench(i, k)) / scale[k];
        if (v > peak) {
          peak = v;
          pk = k;
          pi = i;
        }
      }
    }
    load_note = Fmt(", after the largest load so far (%s = %.4g at t = %.2f s)", kWrenchNames[pk],
                    d.wrench(pi, pk), d.t_s[static_cast<std::size_t>(pi)]);
  }
  const int c = DominantChannel(cx, e.pred);
  e.evidence = Fmt("zero of b%d steps by %+.3g mV/V (%.1f σ) at t = %.2f s and stays%s", c, a(c),
                   std::fabs(a(c)) / cx.sigma(c), onset, load_note.c_str());
  return e;
}

std::optional<EffectFit> FitMains(const Context& cx, const Mat& target) {
  if (cx.peak_hz.empty()) return std::nullopt;
  const auto& d = *cx.data;
  auto fit_at = [&](double f, Mat* out, ChannelFit* cf) {
    const double w = 2.0 * M_PI * f;
    auto r = FitChannels(
        cx, target, 2,
        [&](int i, int, double* x) {
          const double ph = w * d.t_s[static_cast<std::size_t>(i)];
          x[0] = std::cos(ph);
          x[1] = std::sin(ph);
        },
        out);
    if (cf != nullptr) *cf = r;
    return r.sse_w;
  };
  double best_f = 0.0;
  double best_sse = std::numeric_limits<double>::infinity();
  const double duration = d.t_s.back() - d.t_s.front();
  const double bin = cx.rate_hz / static_cast<double>(WelchSegment(static_cast<std::size_t>(cx.n)));
  for (std::size_t p = 0; p < std::min<std::size_t>(cx.peak_hz.size(), 3); ++p) {
    std::vector<double> grid;
    for (int j = -8; j <= 8; ++j) grid.push_back(cx.peak_hz[p] + bin * j / 8.0);
    double fmin = 0.0;
    const double f =
        MinimizeOnGrid([&](double v) { return fit_at(v, nullptr, nullptr); }, grid, 0, &fmin);
    // Final refinement to a fraction of 1/duration.
    std::vector<double> fine;
    for (int j = -4; j <= 4; ++j) fine.push_back(f + bin / 8.0 * j / 4.0);
    const double f2 =
        MinimizeOnGrid([&](double v) { return fit_at(v, nullptr, nullptr); }, fine, 30, &fmin);
    if (fmin < best_sse) {
      best_sse = fmin;
      best_f = f2;
    }
  }
  EffectFit e;
  e.name = "mains_interference";
  e.n_params = 2 * cx.nc + 1;
  ChannelFit cf;
  e.train_sse_w = fit_at(best_f, &e.pred, &cf);
  e.params["freq_hz"] = best_f;
  e.sigma["freq_hz"] = JsonNum(CurvatureSigma([&](double v) { return fit_at(v, nullptr, nullptr); },
                                              best_f, 0.05 / std::max(duration, 1.0)));
  Vec amp(cx.nc);
  for (int c = 0; c < cx.nc; ++c) amp(c) = std::hypot(cf.beta(0, c), cf.beta(1, c));
  e.params["amplitude_mvv"] = VecJson(amp);
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence = Fmt(
      "a steady line at %.3f Hz on %s, %.3g mV/V (%.1f σ) on b%d, present at every load and time",
      best_f, ChannelList(e.channels).c_str(), amp(c), amp(c) / cx.sigma(c), c);
  return e;
}

std::optional<EffectFit> FitResonance(const Context& cx, const Mat& target) {
  const auto& d = *cx.data;
  const double nyq = 0.5 * cx.rate_hz;
  Mat h(cx.n, cx.nc);
  // Coarse search on the two channels with the most residual energy.
  std::vector<int> order(static_cast<std::size_t>(cx.nc));
  for (int c = 0; c < cx.nc; ++c) order[static_cast<std::size_t>(c)] = c;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return target.col(a).squaredNorm() * cx.weight(a) > target.col(b).squaredNorm() * cx.weight(b);
  });
  auto build = [&](double f, double z, const std::vector<int>& chans) {
    std::vector<const double*> in;
    std::vector<double*> out;
    for (int c : chans) {
      in.push_back(d.sim_mvv.col(c).data());
      out.push_back(h.col(c).data());
    }
    SecondOrderLowPassColumns(d.t_s.data(), static_cast<std::size_t>(cx.n), f, z, in.data(),
                              out.data(), in.size(), Restarts(cx));
    for (int c : chans) h.col(c) -= d.sim_mvv.col(c);
  };
  int st = cx.search_stride;
  auto sse_for = [&](double f, double z, const std::vector<int>& chans, Mat* out, ChannelFit* cf) {
    if (f <= 0.05 || f >= 0.98 * nyq || z <= 1e-4 || z > 2.0)
      return std::numeric_limits<double>::infinity();
    build(f, z, chans);
    auto r = FitChannels(
        cx, target, 1, [&](int i, int c, double* x) { x[0] = h(i, c); }, out, &chans,
        out != nullptr || cf != nullptr ? 1 : st);
    if (cf != nullptr) *cf = r;
    double s = 0.0;
    for (int c : chans) s += r.sse(c) * cx.weight(c);
    return s;
  };
  const std::vector<int> coarse(order.begin(), order.begin() + std::min(2, cx.nc));
  std::vector<int> all(static_cast<std::size_t>(cx.nc));
  for (int c = 0; c < cx.nc; ++c) all[static_cast<std::size_t>(c)] = c;
  std::vector<double> fgrid;
  for (std::size_t p = 0; p < std::min<std::size_t>(cx.peak_hz.size(), 3); ++p) {
    for (double m : {0.92, 1.0, 1.08}) fgrid.push_back(cx.peak_hz[p] * m);
  }
  if (fgrid.empty()) {
    for (int j = 0; j < 12; ++j)
      fgrid.push_back(std::exp(std::log(1.0) + (std::log(0.9 * nyq) - std::log(1.0)) * j / 11.0));
  }
  const double zgrid[] = {0.01, 0.03, 0.1, 0.3};
  double bf = 0.0;
  double bz = 0.0;
  double bs = std::numeric_limits<double>::infinity();
  for (double f : fgrid) {
    for (double z : zgrid) {
      const double s = sse_for(f, z, coarse, nullptr, nullptr);
      if (s < bs) {
        bs = s;
        bf = f;
        bz = z;
      }
    }
  }
  if (!std::isfinite(bs)) return std::nullopt;
  // Alternate golden refinements in log f and log ζ on all channels.
  double lf = std::log(bf);
  double lz = std::log(bz);
  for (int round = 0; round < 2; ++round) {
    const std::vector<int>& chans = coarse;  // all channels only in the final fit
    if (round == 1) st = std::max(1, st / 2);
    std::vector<double> g1;
    for (int j = -2; j <= 2; ++j) g1.push_back(lf + 0.04 * j / (round + 1));
    lf = MinimizeOnGrid(
        [&](double v) { return sse_for(std::exp(v), std::exp(lz), chans, nullptr, nullptr); }, g1,
        7, nullptr);
    std::vector<double> g2;
    for (int j = -2; j <= 2; ++j) g2.push_back(lz + 0.3 * j / (round + 1));
    lz = MinimizeOnGrid(
        [&](double v) { return sse_for(std::exp(lf), std::exp(v), chans, nullptr, nullptr); }, g2,
        7, nullptr);
  }
  EffectFit e;
  e.name = "resonance";
  e.n_params = cx.nc + 2;
  ChannelFit cf;
  const double f = std::exp(lf);
  const double z = std::exp(lz);
  e.train_sse_w = sse_for(f, z, all, &e.pred, &cf);
  e.params["freq_hz"] = f;
  e.params["damping_ratio"] = z;
  e.params["damped_freq_hz"] = f * std::sqrt(std::max(0.0, 1.0 - z * z));
  e.sigma["freq_hz"] = JsonNum(
      f * CurvatureSigma([&](double v) { return sse_for(std::exp(v), z, all, nullptr, nullptr); },
                         lf, 0.002));
  e.sigma["damping_ratio"] = JsonNum(
      z * CurvatureSigma([&](double v) { return sse_for(f, std::exp(v), all, nullptr, nullptr); },
                         lz, 0.02));
  Vec gain = cf.beta.row(0).transpose();
  e.params["participation"] = VecJson(gain);
  e.channels = ActiveChannels(cx, e.pred);
  // Count fast load changes: steps where |Δsim| per sample exceeds 20 σ on the dominant channel.
  const int c = DominantChannel(cx, e.pred);
  int fast = 0;
  bool in_fast = false;
  for (int i = 1; i < cx.n; ++i) {
    const bool now = std::fabs(d.sim_mvv(i, c) - d.sim_mvv(i - 1, c)) > 20.0 * cx.sigma(c);
    if (now && !in_fast) ++fast;
    in_fast = now;
  }
  e.evidence =
      Fmt("ringing at %.2f Hz (damping ratio %.3f) after the %d fast load changes on b%d, quiet "
          "during slow ramps and holds, r = %.2f",
          e.params["damped_freq_hz"].get<double>(), z, fast, c, RowCorr(cx, target, e.pred, c));
  return e;
}

}  // namespace

Context MakeContext(const DiagData& d, double block_s, const Eigen::VectorXd* sigma) {
  Context cx;
  cx.data = &d;
  cx.n = static_cast<int>(d.rows());
  cx.nc = d.channels();
  cx.resid = d.real_mvv - d.sim_mvv;
  cx.rate_hz = d.rate_hz();
  cx.dt = 1.0 / cx.rate_hz;
  cx.uniform = true;
  for (std::size_t i = 1; i < d.t_s.size(); ++i) {
    if (std::fabs(d.t_s[i] - d.t_s[i - 1] - cx.dt) > 1e-6 * cx.dt + 1e-9) {
      cx.uniform = false;
      break;
    }
  }
  cx.sigma.resize(cx.nc);
  cx.weight.resize(cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    double s = RobustNoise(cx.resid.col(c).data(), static_cast<std::size_t>(cx.n), cx.rate_hz);
    // Floor: a tiny fraction of the channel's signal scale, so identical files do not divide by 0.
    const double scale = std::max(1e-9, d.sim_mvv.col(c).cwiseAbs().maxCoeff() * 1e-9);
    s = std::max(s, scale);
    if (sigma != nullptr) s = (*sigma)(c);
    cx.sigma(c) = s;
    cx.weight(c) = 1.0 / (s * s);
  }
  // Hold-out: interleaved blocks of about block_s (≥ 20 rows, ≥ 30 blocks), every third held out.
  auto rows_per_block = static_cast<std::size_t>(std::max(20.0, std::round(block_s * cx.rate_hz)));
  rows_per_block = std::min(rows_per_block, std::max<std::size_t>(4, d.rows() / 30));
  cx.block_s = static_cast<double>(rows_per_block) * cx.dt;
  cx.search_stride = std::max(1, static_cast<int>(std::lround(cx.n / 12000.0)));
  cx.train.resize(d.rows());
  if (!d.segment.empty()) {
    cx.restart.assign(d.rows(), 0);
    for (std::size_t i = 1; i < d.rows(); ++i) {
      if (d.segment[i] != d.segment[i - 1]) {
        cx.restart[i] = 1;
        ++cx.segments;
      }
    }
  }
  // Blocks restart at every segment boundary (a short last block is closed there).
  std::size_t block = 0;
  std::size_t in_block = 0;
  for (std::size_t i = 0; i < d.rows(); ++i) {
    if (i > 0 && (in_block == rows_per_block || (!cx.restart.empty() && cx.restart[i] != 0))) {
      ++block;
      in_block = 0;
    }
    ++in_block;
    cx.train[i] = (block % 3) == 1 ? 0 : 1;
    if (cx.train[i]) {
      ++cx.n_train;
    } else {
      ++cx.n_hold;
    }
  }
  // Zero and sensitivity of the sim by regression on the wrench.
  cx.zero = Vec::Zero(cx.nc);
  cx.sens = Mat::Zero(cx.nc, 6);
  if (d.has_wrench()) {
    for (int c = 0; c < cx.nc; ++c) {
      NormalEq ne(7);
      double x[7];
      for (int i = 0; i < cx.n; ++i) {
        x[0] = 1.0;
        for (int k = 0; k < 6; ++k) x[k + 1] = d.wrench(i, k);
        ne.Add(x, d.sim_mvv(i, c));
      }
      const auto r = ne.Solve();
      cx.zero(c) = r.beta(0);
      for (int k = 0; k < 6; ++k) cx.sens(c, k) = r.beta(k + 1);
    }
  }
  cx.load = d.sim_mvv.rowwise() - cx.zero.transpose();
  cx.load_range.resize(cx.nc);
  for (int c = 0; c < cx.nc; ++c)
    cx.load_range(c) = cx.load.col(c).maxCoeff() - cx.load.col(c).minCoeff();
  if (d.has_temp()) {
    double lo = d.temp_c.front();
    double hi = lo;
    for (double v : d.temp_c) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (hi - lo > 1e-6) {
      cx.dtemp.resize(d.rows());
      for (std::size_t i = 0; i < d.rows(); ++i) cx.dtemp[i] = d.temp_c[i] - 20.0;
    }
  }
  // Spectral lines of the whitened residual, summed over channels.
  const std::size_t seg = WelchSegment(d.rows());
  if (d.rows() >= seg && seg >= 32) {
    std::vector<double> total;
    std::vector<double> freq;
    for (int c = 0; c < cx.nc; ++c) {
      const Spectrum s = Welch(cx.resid.col(c).data(), d.rows(), cx.rate_hz, seg);
      if (total.empty()) {
        total.assign(s.power.size(), 0.0);
        freq = s.freq_hz;
      }
      for (std::size_t k = 0; k < s.power.size(); ++k) total[k] += s.power[k] * cx.weight(c);
    }
    std::vector<double> band(total.begin() + 1, total.end());
    std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2),
                     band.end());
    const double floor = std::max(band[band.size() / 2], 1e-300);
    std::vector<std::pair<double, double>> peaks;
    for (std::size_t k = 3; k + 1 < total.size(); ++k) {
      if (total[k] > total[k - 1] && total[k] >= total[k + 1] && total[k] > 4.0 * floor) {
        peaks.emplace_back(total[k] / floor, freq[k]);
      }
    }
    std::sort(peaks.rbegin(), peaks.rend());
    for (std::size_t j = 0; j < std::min<std::size_t>(peaks.size(), 5); ++j) {
      cx.peak_ratio.push_back(peaks[j].first);
      cx.peak_hz.push_back(peaks[j].second);
    }
  }
  return cx;
}

Sums Score(const Context& cx, const Eigen::MatrixXd& target, const Eigen::MatrixXd* pred) {
  Sums s;
  for (int c = 0; c < cx.nc; ++c) {
    double tr = 0.0;
    double ho = 0.0;
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      const double p = pred != nullptr ? (*pred)(i, c) : 0.0;
      const double e = target(i, c) - p;
      if (cx.train[static_cast<std::size_t>(i)]) {
        tr += e * e;
      } else {
        ho += e * e;
        pp += p * p;
      }
    }
    s.train_sse += tr * cx.weight(c);
    s.hold_sse += ho * cx.weight(c);
    s.hold_pp += pp * cx.weight(c);
  }
  return s;
}

namespace {
std::optional<EffectFit> FitThermalZeroPlain(const Context& cx, const Mat& target) {
  return FitThermalZeroOn(cx, target, cx.dtemp);
}
}  // namespace

const std::vector<EffectSpec>& Effects() {
  static const std::vector<EffectSpec> kEffects = {
      {"zero_offset", &FitZeroOffset},
      {"zero_drift", &FitZeroDrift},
      {"thermal_zero_drift", &FitThermalZeroPlain},
      {"thermal_span_drift", &FitThermalSpan},
      {"excitation_drift", &FitExcitation},
      {"creep", &FitCreep},
      {"hysteresis", &FitHysteresisFamily},
      {"bridge_nonlinearity", &FitBridgeNonlinearity},
      {"geometric_nonlinearity", &FitGeometric},
      {"load_stiffening", &FitLoadStiffening},
      {"misalignment", &FitMisalignment},
      {"gain_error", &FitGainError},
      {"time_skew", &FitTimeSkew},
      {"saturation", &FitSaturation},
      {"overload_shift", &FitOverloadShift},
      {"mains_interference", &FitMains},
      {"resonance", &FitResonance},
  };
  return kEffects;
}

const EffectSpec* FindEffect(const std::string& name) {
  for (const auto& e : Effects()) {
    if (name == e.name) return &e;
  }
  return nullptr;
}

}  // namespace ftstack::diag
