// overload_shift: a zero step after an overload, lasting or partly recovering.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/nonlinear_search.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The time the zero steps: the split of the training rows after which a constant per channel
/// explains most of the target (whitened). Also the training times either side of it.
bool FindOnset(const Context& cx, const Series& target, double* onset, double* t_before,
               double* t_after) {
  const auto& d = *cx.data;
  std::vector<int> rows;
  ForTrainingRows(cx, 0, cx.n, [&](int i) { rows.push_back(i); });
  const auto m = rows.size();
  if (m < 40) return false;
  // Suffix sums per channel: a step from 0 to a_c after the split explains Σ_c w_c·S_c²/n_after.
  // Accumulated from the last row and scored on the way (memory: no m × N table); ≥ keeps the
  // earliest split of equal gains.
  std::vector<double> suffix(static_cast<std::size_t>(cx.nc), 0.0);
  double best = -1.0;
  std::size_t bj = 0;
  for (std::size_t j = m; j-- > 10;) {
    for (int c = 0; c < cx.nc; ++c) suffix[static_cast<std::size_t>(c)] += target(rows[j], c);
    if (j + 10 >= m) continue;
    const double na = static_cast<double>(m - j);
    double g = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      const double s = suffix[static_cast<std::size_t>(c)];
      g += cx.weight(c) * s * s / na;
    }
    if (g >= best) {
      best = g;
      bj = j;
    }
  }
  *t_after = d.t_s[static_cast<std::size_t>(rows[bj])];
  *t_before = d.t_s[static_cast<std::size_t>(rows[bj - 1])];
  *onset = rows[bj] - rows[bj - 1] > 1 ? 0.5 * (*t_before + *t_after) : *t_after;
  return true;
}

/// The zero after `onset`: a lasting shift per channel and, with tau_s > 0, a part that recovers
/// as exp(−(t − onset)/tau_s) (a yielded adhesive or flexure relaxing part of the way back).
/// Features of row i: the step, and with tau_s > 0 the recovery.
struct ShiftFeatures {
  const std::vector<double>* t_s;
  double onset;
  double tau_s;
  [[nodiscard]] int Count() const { return tau_s > 0 ? 2 : 1; }
  void operator()(int i, int, double* x) const {
    const double s = (*t_s)[static_cast<std::size_t>(i)] - onset;
    x[0] = s >= 0 ? 1.0 : 0.0;
    if (tau_s > 0) x[1] = s >= 0 ? std::exp(-s / tau_s) : 0.0;
  }
};

ChannelFit FitShift(const Context& cx, const Series& target, const ShiftFeatures& feat) {
  return FitChannels(cx, target, feat.Count(), feat, nullptr);
}

/// The recovery's time-constant range: 3 samples (and 0.2 s) to a third of the time left after the
/// onset (a slower recovery is a drift the record cannot tell from it).
LogBounds RecoveryBounds(const Context& cx, double onset) {
  const double lo = std::max(3.0 * cx.dt, 0.2);
  const double hi = std::max((cx.data->t_s.back() - onset) / 3.0, 2.0 * lo);
  return {std::log(lo), std::log(hi)};
}

/// The declared recovery time constant: RecoveryBounds' ends for an onset at the record's start
/// (the search of a later onset stays inside it).
std::vector<ParamSpec> OverloadShiftSpecs(const Context& cx) {
  const LogBounds b = RecoveryBounds(cx, cx.data->t_s.front());
  return {{.key = "recovery_tau_s",
           .lo = std::exp(b.lo),
           .hi = std::exp(b.hi),
           .lo_what = "3 samples and 0.2 s",
           .hi_what = "a third of the record after the onset",
           .unit = "s",
           .grid_points = 13,
           .golden_steps = 7}};
}

/// The whitened training SSE of the partly recovering shift with time constant tau_s, up to a
/// constant (what the step and the recovery explain, negated): per channel a 2 × 2 solve on sums
/// over the training rows after the onset, one exponential per row for all channels.
double RecoveryObjective(const Context& cx, const Series& target, const std::vector<int>& after,
                         double onset, double tau_s) {
  const auto& t = cx.data->t_s;
  double se = 0.0;
  double see = 0.0;
  std::vector<double> sy(static_cast<std::size_t>(cx.nc), 0.0);
  std::vector<double> sye(static_cast<std::size_t>(cx.nc), 0.0);
  for (const int i : after) {
    const double e = std::exp(-(t[static_cast<std::size_t>(i)] - onset) / tau_s);
    se += e;
    see += e * e;
    for (int c = 0; c < cx.nc; ++c) {
      const double y = target(i, c);
      sy[static_cast<std::size_t>(c)] += y;
      sye[static_cast<std::size_t>(c)] += y * e;
    }
  }
  const double n = static_cast<double>(after.size());
  const double det = n * see - se * se;
  if (!(det > 1e-12 * n * see)) return std::numeric_limits<double>::infinity();
  double explained = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    const double b0 = sy[static_cast<std::size_t>(c)];
    const double b1 = sye[static_cast<std::size_t>(c)];
    explained += cx.weight(c) * (see * b0 * b0 - 2.0 * se * b0 * b1 + n * b1 * b1) / det;
  }
  return -explained;
}

/// The recovery time constant of least training SSE (log grid, then golden rounds), and its
/// log-σ; nullopt when it ends within 2 % (in log) of a bound of RecoveryBounds (not resolved:
/// the lasting step alone is kept).
std::optional<double> RecoveryTau(const Context& cx, const Series& target, double onset,
                                  double* log_sigma) {
  const LogBounds b = RecoveryBounds(cx, onset);
  std::vector<int> after;
  ForTrainingRows(cx, 0, cx.n, [&](int i) {
    if (cx.data->t_s[static_cast<std::size_t>(i)] >= onset) after.push_back(i);
  });
  if (after.size() < 10) return std::nullopt;
  const LogObjective sse = [&](const std::vector<double>& lt) {
    return RecoveryObjective(cx, target, after, onset, std::exp(lt[0]));
  };
  std::vector<std::vector<double>> grid;
  for (int k = 0; k <= 12; ++k) grid.push_back({b.lo + (b.hi - b.lo) * k / 12.0});
  const std::vector<SolvedParam> s = SolveJoint(
      sse, grid, {b}, {(b.hi - b.lo) / 12.0}, 0, 2, [](int) {}, kOnBound);
  if (s.empty() || s[0].status != ParamStatus::kResolved) return std::nullopt;
  *log_sigma = s[0].sigma / s[0].value;
  return s[0].value;
}

/// The load peak nearest before the onset (an overload is the physical cause), in words.
std::string OverloadNote(const Context& cx, double onset) {
  const auto& d = *cx.data;
  if (!d.has_wrench()) return "";
  double peak = 0.0;
  int pk = 0;
  int pi = 0;
  double scale[6];
  for (int k = 0; k < 6; ++k)
    scale[k] = std::max<double>(d.wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
  for (int i = 0; i < cx.n && d.t_s[static_cast<std::size_t>(i)] <= onset + 2.0 * cx.block_s; ++i) {
    for (int k = 0; k < 6; ++k) {
      const double v = std::fabs(d.wrench(i, k)) / scale[k];
      if (v > peak) {
        peak = v;
        pk = k;
        pi = i;
      }
    }
  }
  return Fmt(", after the largest load so far (%s = %.4g at t = %.2f s)", kWrenchAxisNames[pk],
             d.wrench(pi, pk), d.t_s[static_cast<std::size_t>(pi)]);
}

}  // namespace

std::optional<EffectFit> FitOverloadShift(const Context& cx, const Series& target) {
  double onset = 0.0;
  double t_before = 0.0;
  double t_after = 0.0;
  if (!FindOnset(cx, target, &onset, &t_before, &t_after)) return std::nullopt;
  EffectFit e;
  e.name = "overload_shift";
  e.n_params = cx.nc + 1;
  // Both variants fitted without a prediction; the kept one predicts last, from its coefficients.
  ShiftFeatures kept{&cx.data->t_s, onset, 0.0};
  ChannelFit f = FitShift(cx, target, kept);
  // A shift that partly recovers: kept by the training BIC (nc + 1 more parameters) and only with
  // its time constant resolved inside its range.
  double log_sigma = 0.0;
  const std::optional<double> tau = RecoveryTau(cx, target, onset, &log_sigma);
  if (tau) {
    const ShiftFeatures recovering{&cx.data->t_s, onset, *tau};
    ChannelFit g = FitShift(cx, target, recovering);
    const double log_n = std::log(std::max<double>(2.0, static_cast<double>(cx.n_train)));
    if (g.sse_w + (cx.nc + 1) * log_n < f.sse_w) {
      f = std::move(g);
      kept = recovering;
      e.n_params = 2 * cx.nc + 2;
      e.variant = "partly recovering";
      e.params["recovery_tau_s"] = *tau;
      e.sigma["recovery_tau_s"] = *tau * log_sigma;
      PutChannelCoef(cx, f, 1, "recovering_shift", &e);
    }
  }
  PredictChannels(cx, f, kept.Count(), kept, &e.pred);
  e.train_sse_w = f.sse_w;
  const Vec a = PutChannelCoef(cx, f, 0, "shift", &e);
  e.params["onset_s"] = onset;
  e.sigma["onset_s"] = std::max(cx.dt, (t_after - t_before) / std::sqrt(12.0));
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  const std::string recovery = e.variant.empty()
                                   ? "stays"
                                   : Fmt("stays after %+.3g mV/V of it recovers with τ = %.3g s",
                                         e.params["recovering_shift"][c].get<double>(), *tau);
  e.evidence =
      Fmt("zero of b%d steps by %+.3g mV/V (%.1f σ) at t = %.2f s and %s%s", c, a(c),
          std::fabs(a(c)) / cx.sigma(c), onset, recovery.c_str(), OverloadNote(cx, onset).c_str());
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec OverloadShiftPlugin() {
  return {.kind = EffectKind::kOverloadShift,
          .traits = kTimeBased,
          .confounders = kConfoundersOfTime,
          .fit = &fx::FitOverloadShift,
          .ranges = &fx::OverloadShiftSpecs};
}

}  // namespace ftstack::diag
