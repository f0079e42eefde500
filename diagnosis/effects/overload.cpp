// Overload effects: saturation (clipping) and overload_shift (a permanent zero step).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitSaturation(const Context& cx, const Series& target) {
  // Real = sim + residual; a clipping limit shows up as the extremes of the real outputs.
  double hi = -std::numeric_limits<double>::infinity();
  double lo = std::numeric_limits<double>::infinity();
  double sim_hi = hi;
  double sim_lo = lo;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      const double s = cx.sim_mvv(i, c);
      const double r = s + target(i, c);
      hi = std::max(hi, r);
      lo = std::min(lo, r);
      sim_hi = std::max(sim_hi, s);
      sim_lo = std::min(sim_lo, s);
    }
  }
  // Clipping needs the sim to go beyond what the real file ever reads.
  if (sim_hi <= hi && sim_lo >= lo) return std::nullopt;
  auto predict = [&](double l, double h, Series* out) {
    double sse = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      double acc = 0.0;
      for (int i = 0; i < cx.n; ++i) {
        const double s = cx.sim_mvv(i, c);
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
      if (std::fabs(cx.sim_mvv(i, c)) > l) ++pinned;
    }
  }
  e.evidence = Fmt(
      "%d samples where the sim exceeds %.4g mV/V read back pinned at the limit (sim reaches %.4g)",
      pinned, l, std::max(std::fabs(sim_lo), std::fabs(sim_hi)));
  return e;
}

std::optional<EffectFit> FitOverloadShift(const Context& cx, const Series& target) {
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
    for (int k = 0; k < 6; ++k)
      scale[k] = std::max<double>(d.wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
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

}  // namespace ftstack::diag::fx
