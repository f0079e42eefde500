// resonance, variant "ringing per load change": a lightly damped mode whose ringing each load
// change starts afresh with its own amplitude and phase per channel (a weight hung by hand swings
// as it was let go, not as the reference's step says). For given (f, ζ) the model is linear: two
// decaying quadrature columns per load change and channel, each active from its change to the next.
// (f, ζ) are shared and searched from the residual's median-periodogram lines.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/nonlinear_search.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The variant's physical range, narrower than resonance's (ResonanceSpecs): light damping only
/// (heavier "ringing" with a free start per change would mimic per-hold offsets and creep), and at
/// least kMinPeriods periods in the median stretch between changes.
constexpr double kMinZeta = 1e-3;
constexpr double kMaxZeta = 0.05;
constexpr double kMinPeriods = 3.0;
/// The first periods after a change are not fitted (the prediction extends back over them): the
/// hand letting go and the hanger's bounce are not this mode's ringing, and would pull ζ up.
constexpr double kSettlePeriods = 3.0;

/// The ringing's search bounds in (log f, log ζ): its declared ranges.
std::vector<LogBounds> RingBounds(const std::vector<ParamSpec>& specs) {
  return {{std::log(specs[0].lo), std::log(specs[0].hi)},
          {std::log(specs[1].lo), std::log(specs[1].hi)}};
}

/// Whether the ringing at (log f, log ζ) ended inside its declared ranges (the engine's rule).
bool Resolved(const std::vector<ParamSpec>& specs, const std::vector<double>& x) {
  return StatusOf(specs[0], std::exp(x[0])) == ParamStatus::kResolved &&
         StatusOf(specs[1], std::exp(x[1])) == ParamStatus::kResolved;
}

/// The two quadrature columns e^{−ζωt}·(cos ω_d t, sin ω_d t) of the ringing started at row a.
struct Quadrature {
  double w = 0.0;
  double wd = 0.0;
  double zw = 0.0;
  Quadrature(double f_hz, double zeta)
      : w(2.0 * std::numbers::pi * f_hz),
        wd(w * std::sqrt(std::max(0.0, 1.0 - zeta * zeta))),
        zw(zeta * w) {}
  void At(double t_s, double* x) const {
    const double env = std::exp(-zw * t_s);
    x[0] = env * std::cos(wd * t_s);
    x[1] = env * std::sin(wd * t_s);
  }
};

/// Coefficients per stretch and channel: beta[k·nc + c] = (cos, sin) amplitude, mV/V.
struct RingFit {
  std::vector<Eigen::Vector2d> beta;
  double sse_w = 0.0;  ///< whitened training SSE over `chans`
};

/// Fits the ringing at (f, ζ) on `chans`, on every row_step-th training row from settle_s after
/// each change: per stretch and channel a 2 × 2 least squares (the stretches' columns do not
/// overlap). The settling rows, settle_s after each change, are left out of the fit and of sse_w.
RingFit FitRing(const Context& cx, const Series& target, const std::vector<int>& starts,
                double f_hz, double zeta, double settle_s, const std::vector<int>& chans,
                int row_step) {
  const Quadrature q(f_hz, zeta);
  RingFit out;
  out.beta.assign(starts.size() * static_cast<std::size_t>(cx.nc), Eigen::Vector2d::Zero());
  const auto& t = cx.data->t_s;
  ForTrainingRows(
      cx, 0, starts.empty() ? cx.n : starts[0],
      [&](int i) {
        for (int c : chans) out.sse_w += double(target(i, c)) * target(i, c) * cx.weight(c);
      },
      row_step);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const int a = starts[k];
    const int b = k + 1 < starts.size() ? starts[k + 1] : cx.n;
    const double settled = t[static_cast<std::size_t>(a)] + settle_s;
    for (int c : chans) {
      Eigen::Matrix2d aa = Eigen::Matrix2d::Zero();
      Eigen::Vector2d ay = Eigen::Vector2d::Zero();
      double yy = 0.0;
      double x[2];
      ForTrainingRows(
          cx, a, b,
          [&](int i) {
            if (t[static_cast<std::size_t>(i)] < settled) return;
            q.At(t[static_cast<std::size_t>(i)] - t[static_cast<std::size_t>(a)], x);
            const double y = target(i, c);
            aa(0, 0) += x[0] * x[0];
            aa(0, 1) += x[0] * x[1];
            aa(1, 1) += x[1] * x[1];
            ay(0) += x[0] * y;
            ay(1) += x[1] * y;
            yy += y * y;
          },
          row_step);
      aa(1, 0) = aa(0, 1);
      Eigen::Vector2d beta = Eigen::Vector2d::Zero();
      if (aa.determinant() > 1e-12 * std::max(1.0, aa.trace() * aa.trace()))
        beta = aa.ldlt().solve(ay);
      out.beta[k * static_cast<std::size_t>(cx.nc) + static_cast<std::size_t>(c)] = beta;
      out.sse_w += std::max(0.0, yy - beta.dot(ay)) * cx.weight(c);
    }
  }
  return out;
}

/// The prediction of a fit on every row (0 before the first load change).
Series PredictRing(const Context& cx, const std::vector<int>& starts, double f_hz, double zeta,
                   const RingFit& r) {
  const Quadrature q(f_hz, zeta);
  Series pred = Series::Zero(cx.n, cx.nc);
  const auto& t = cx.data->t_s;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const int a = starts[k];
    const int b = k + 1 < starts.size() ? starts[k + 1] : cx.n;
    double x[2];
    for (int i = a; i < b; ++i) {
      q.At(t[static_cast<std::size_t>(i)] - t[static_cast<std::size_t>(a)], x);
      for (int c = 0; c < cx.nc; ++c) {
        const auto& bc = r.beta[k * static_cast<std::size_t>(cx.nc) + static_cast<std::size_t>(c)];
        pred(i, c) = static_cast<float>(bc(0) * x[0] + bc(1) * x[1]);
      }
    }
  }
  return pred;
}

/// Lines to search at: the residual's median-periodogram lines (LocalLines, most prominent first)
/// then the strongest Welch lines, inside the bounds, none within 3 % of another; at most 4.
std::vector<double> RingLines(const Context& cx, const Series& target, const LogBounds& f) {
  std::vector<double> cand;
  // Weak lines too (1.5 × their neighbourhood): a ringing restarted at every change with its own
  // phase spreads over the segments; the training BIC decides whether one is kept.
  for (const auto& [level, f_hz] : LocalLines(cx, target, 1.5)) cand.push_back(f_hz);
  for (std::size_t j = 0; j < std::min<std::size_t>(3, cx.peak_hz.size()); ++j)
    cand.push_back(cx.peak_hz[j]);
  std::vector<double> out;
  for (double line : cand) {
    const double g = std::log(line);
    const bool apart = std::none_of(out.begin(), out.end(),
                                    [&](double o) { return std::fabs(g - std::log(o)) < 0.03; });
    if (apart && g > f.lo && g < f.hi && out.size() < 4) out.push_back(line);
  }
  return out;
}

/// target minus, per row and channel, the mean of the training rows of its stretch within ±half
/// of `window_rows` (held-out rows never enter a training row's mean): creep, zero shifts and the
/// settling after a change, slow against the ringing, leave the search's objective.
Series Detrended(const Context& cx, const Series& target, const std::vector<int>& starts,
                 int window_rows) {
  Series out = target;
  const int half = std::max(1, window_rows / 2);
  std::vector<double> sum(static_cast<std::size_t>(cx.n) + 1);
  std::vector<int> cnt(static_cast<std::size_t>(cx.n) + 1);
  for (int c = 0; c < cx.nc; ++c) {
    ForRowsWithTraining(cx, 0, cx.n, [&](int i, bool tr) {
      sum[static_cast<std::size_t>(i) + 1] =
          sum[static_cast<std::size_t>(i)] + (tr ? target(i, c) : 0.0);
      cnt[static_cast<std::size_t>(i) + 1] = cnt[static_cast<std::size_t>(i)] + (tr ? 1 : 0);
    });
    for (std::size_t k = 0; k <= starts.size(); ++k) {
      const int a = k == 0 ? 0 : starts[k - 1];
      const int b = k < starts.size() ? starts[k] : cx.n;
      for (int i = a; i < b; ++i) {
        const auto lo = static_cast<std::size_t>(std::max(a, i - half));
        const auto hi = static_cast<std::size_t>(std::min(b, i + half + 1));
        const int m = cnt[hi] - cnt[lo];
        if (m > 0) out(i, c) = static_cast<float>(target(i, c) - (sum[hi] - sum[lo]) / m);
      }
    }
  }
  return out;
}

/// Participation per channel: Σ onset amplitude / Σ |load change| over the changes (a share of the
/// step; the phase is free, so no sign).
Vec Participation(const Context& cx, const std::vector<int>& starts, const RingFit& r) {
  Vec p = Vec::Zero(cx.nc);
  for (int c = 0; c < cx.nc; ++c) {
    double amp = 0.0;
    double step = 0.0;
    for (std::size_t k = 0; k < starts.size(); ++k) {
      const int a = starts[k];
      const int b = k + 1 < starts.size() ? starts[k + 1] : cx.n;
      amp += r.beta[k * static_cast<std::size_t>(cx.nc) + static_cast<std::size_t>(c)].norm();
      step += std::fabs(cx.load(b - 1, c) - cx.load(std::max(a - 1, 0), c));
    }
    p(c) = step > 0.0 ? amp / step : 0.0;
  }
  return p;
}

/// The ringing's (log f, log ζ) searched near one line, on the target detrended over 4 of the
/// line's periods: the coarse grid (±1.5 % × ζ 0.001 … 0.03) or `warm`, then golden rounds.
/// False when no start point has a finite objective.
bool SearchNearLine(const Context& cx, const Series& detrended, const std::vector<int>& starts,
                    const std::vector<LogBounds>& bounds, double line_hz, const double* warm,
                    std::vector<double>* best) {
  const std::vector<int> all = AllChannels(cx);
  int row_step = cx.search_stride;
  const double settle_s = kSettlePeriods / line_hz;
  const LogObjective sse = [&](const std::vector<double>& x) {
    return FitRing(cx, detrended, starts, std::exp(x[0]), std::exp(x[1]), settle_s, all, row_step)
        .sse_w;
  };
  *best = {std::log(line_hz), std::log(0.01)};
  if (warm != nullptr) {
    *best = {warm[0], warm[1]};
  } else {
    std::vector<std::vector<double>> points;
    for (double m : {0.985, 1.0, 1.015}) {
      for (double z : {0.001, 0.003, 0.01, 0.03})
        points.push_back({std::log(line_hz * m), std::log(z)});
    }
    if (!std::isfinite(JointStart(sse, points, best))) return false;
  }
  (void)JointRefine(
      sse, bounds, {0.01, 0.4}, warm != nullptr ? 1 : 0, 2,
      [&](int round) {
        if (round == 1) row_step = 1;
      },
      best);
  return true;
}

}  // namespace

std::vector<ParamSpec> RingingSpecs(const Context& cx) {
  const std::vector<int> starts = LoadChangeStarts(cx);
  double median_s = std::numeric_limits<double>::infinity();
  if (!starts.empty()) {
    std::vector<double> len;
    for (std::size_t k = 0; k < starts.size(); ++k) {
      const int b = k + 1 < starts.size() ? starts[k + 1] : cx.n;
      len.push_back((b - starts[k]) * cx.dt);
    }
    std::nth_element(len.begin(), len.begin() + std::ssize(len) / 2, len.end());
    median_s = std::max(len[len.size() / 2], 1e-9);
  }
  return {
      {.key = "freq_hz",
       .lo = std::max(0.05, kMinPeriods / median_s),
       .hi = 0.98 * 0.5 * cx.rate_hz,
       .lo_what = "3 periods in the median stretch between load changes (or 0.05 Hz)",
       .hi_what = "0.98 × Nyquist",
       .unit = "Hz"},
      {.key = "damping_ratio",
       .lo = kMinZeta,
       .hi = kMaxZeta,
       .lo_what = "Q 500",
       .hi_what = "light damping (heavier ringing restarted per change mimics per-hold offsets)",
       .unit = ""}};
}

std::vector<int> LoadChangeStarts(const Context& cx) {
  std::vector<int> s;
  for (const Transition& tr : cx.conditioning.transitions) s.push_back(tr.first_row);
  for (std::size_t i = 0; i < cx.restart.size(); ++i) {
    if (cx.restart[i] != 0) s.push_back(static_cast<int>(i));
  }
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

std::optional<EffectFit> RingingPerChange(const Context& cx, const Series& target,
                                          const EffectFit* near, bool uncertainty) {
  const std::vector<int> starts = LoadChangeStarts(cx);
  if (starts.empty() || cx.data == nullptr || std::ssize(cx.data->t_s) != cx.n) return std::nullopt;
  const std::vector<ParamSpec> specs = RingingSpecs(cx);
  const std::vector<LogBounds> bounds = RingBounds(specs);
  const bool warm = near != nullptr && near->search_state.size() == 3;
  const std::vector<double> lines = warm ? std::vector<double>{std::exp(near->search_state[2])}
                                         : RingLines(cx, target, bounds[0]);
  // Per line: the search on the detrended target, the coefficients from it, scored on the target;
  // a line resolved inside the declared ranges beats one on a bound (which the engine then
  // reports not resolved).
  double best_sse = std::numeric_limits<double>::infinity();
  bool best_resolved = false;
  std::vector<double> best;
  Series detrended;
  for (double line : lines) {
    const int window = static_cast<int>(std::lround(4.0 * cx.rate_hz / line));
    Series d = Detrended(cx, target, starts, window);
    const double settle_s = kSettlePeriods / line;
    std::vector<double> x;
    if (!SearchNearLine(cx, d, starts, bounds, line, warm ? near->search_state.data() : nullptr,
                        &x))
      continue;
    const bool resolved = Resolved(specs, x);
    if (best_resolved && !resolved) continue;
    const RingFit r =
        FitRing(cx, d, starts, std::exp(x[0]), std::exp(x[1]), settle_s, AllChannels(cx), 1);
    const Series pred = PredictRing(cx, starts, std::exp(x[0]), std::exp(x[1]), r);
    const double s = Score(cx, target, &pred).train_sse;
    if (s < best_sse || (resolved && !best_resolved)) {
      best_sse = s;
      best_resolved = resolved;
      best = {x[0], x[1], std::log(line)};
      detrended = std::move(d);
    }
  }
  if (best.empty()) return std::nullopt;
  const std::vector<int> all = AllChannels(cx);
  const double f = std::exp(best[0]);
  const double z = std::exp(best[1]);
  const double settle_s = kSettlePeriods / std::exp(best[2]);
  const RingFit fit = FitRing(cx, detrended, starts, f, z, settle_s, all, 1);
  EffectFit e;
  e.name = "resonance";
  e.variant = kRingingPerChange;
  e.n_params = 2 + 2 * static_cast<int>(starts.size()) * cx.nc;
  e.pred = PredictRing(cx, starts, f, z, fit);
  e.train_sse_w = best_sse;
  e.params["freq_hz"] = f;
  e.params["damping_ratio"] = z;
  e.params["damped_freq_hz"] = f * std::sqrt(std::max(0.0, 1.0 - z * z));
  e.params["load_changes"] = static_cast<int>(starts.size());
  e.params["participation"] = VecJson(Participation(cx, starts, fit));
  if (uncertainty) {
    const auto at = [&](double lf, double lz) {
      return FitRing(cx, detrended, starts, std::exp(lf), std::exp(lz), settle_s, all, 1).sse_w;
    };
    e.sigma["freq_hz"] = JsonNum(f * ProfileSigma([&](double v) { return at(v, best[1]); }, best[0],
                                                  std::min(0.002, 0.25 * z)));
    e.sigma["damping_ratio"] =
        JsonNum(z * ProfileSigma([&](double v) { return at(best[0], v); }, best[1], kOnBound));
  }
  e.search_state = best;
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("ringing at %.4g Hz (damping ratio %.3g, Q %.0f) started afresh at each of the %zu load "
          "changes with its own amplitude and phase (not locked to the reference's step), onset "
          "amplitude %.2g %% of the step on b%d, r = %.2f",
          f, z, 0.5 / z, starts.size(), 100.0 * e.params["participation"][c].get<double>(), c,
          RowCorr(cx, target, e.pred, c));
  return e;
}

}  // namespace ftstack::diag::fx
