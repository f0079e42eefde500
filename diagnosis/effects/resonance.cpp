// resonance: the ringing of a second-order mode excited by the load's steps, (f, ζ) searched on a
// coarse grid then refined; and a second mode, searched at the lines of the one-mode fit's residual
// spectrum and fitted jointly with the first, kept only when the training BIC says so.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/nonlinear_search.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// Fast load changes on channel c: runs of rows where |Δsim| per sample exceeds 20 σ.
int FastLoadChanges(const Context& cx, int c) {
  int fast = 0;
  bool in_fast = false;
  for (int i = 1; i < cx.n; ++i) {
    const bool now = std::fabs(cx.sim_mvv(i, c) - cx.sim_mvv(i - 1, c)) > 20.0 * cx.sigma(c);
    if (now && !in_fast) ++fast;
    in_fast = now;
  }
  return fast;
}

/// The physical range of a mode, which is also its search's: below 0.98 × Nyquist, above
/// kMinFreqHz; damping ratio from kMinZeta (Q 500: a swinging weight, a fixture mode) to kMaxZeta
/// (beyond it a step response barely rings: a lag, not a resonance).
constexpr double kMinFreqHz = 0.05;
constexpr double kMinZeta = 1e-3;
constexpr double kMaxZeta = 0.5;
double MaxFreqHz(const Context& cx) { return 0.98 * 0.5 * cx.rate_hz; }
bool InRange(const Context& cx, double f_hz, double zeta) {
  return f_hz >= kMinFreqHz && f_hz <= MaxFreqHz(cx) && zeta >= kMinZeta && zeta <= kMaxZeta;
}

/// Resonance's physical ranges (those of its search): every mode below Nyquist, lightly damped.
std::vector<ParamSpec> ResonanceSpecs(const Context& cx) {
  const double f_hi = MaxFreqHz(cx);
  return {{"freq_hz", kMinFreqHz, f_hi, "0.05 Hz", "0.98 × Nyquist", "Hz"},
          {"damping_ratio", kMinZeta, kMaxZeta, "Q 500", "a step response that rings"},
          {"freq2_hz", kMinFreqHz, f_hi, "0.05 Hz", "0.98 × Nyquist", "Hz"},
          {"damping_ratio2", kMinZeta, kMaxZeta, "Q 500", "a step response that rings"}};
}

/// The ranges of one resonance fit: its variant's where that searches narrower ones.
std::vector<ParamSpec> ResonanceFitSpecs(const Context& cx, const EffectFit& fit) {
  return fit.variant == kRingingPerChange ? RingingSpecs(cx) : ResonanceSpecs(cx);
}

/// The coarse frequency grid: ±8 % around each of the 3 strongest lines of the residual spectrum
/// and of the 3 lines standing most out of their neighbourhood (LocalLines: a light ringing under
/// a red spectrum), or 12 log-spaced points from 1 Hz to 0.9 × Nyquist without any.
std::vector<double> ResonanceGrid(const Context& cx, const Series& target) {
  std::vector<double> lines(
      cx.peak_hz.begin(), cx.peak_hz.begin() + std::min<std::ptrdiff_t>(std::ssize(cx.peak_hz), 3));
  int local = 0;
  for (const auto& [level, f_hz] : LocalLines(cx, target)) {
    const bool apart = std::none_of(lines.begin(), lines.end(), [f = f_hz](double g) {
      return std::fabs(std::log(f / g)) < 0.08;
    });
    if (apart && local++ < 3) lines.push_back(f_hz);
  }
  std::vector<double> fgrid;
  for (double line : lines) {
    for (double m : {0.92, 1.0, 1.08}) fgrid.push_back(line * m);
  }
  if (fgrid.empty()) {
    for (int j = 0; j < 12; ++j) fgrid.push_back(std::exp(std::log(0.45 * cx.rate_hz) * j / 11.0));
  }
  return fgrid;
}

/// Rows of ringing searches' coarse stage: [0, n) up to kCoarseRows rows, else the kCoarseRows
/// consecutive rows carrying the most load-step energy Σ w_c·(Δsim_c)² on `chans` (the ringing is
/// excited there; the filter starts at rest at the window's first row and restarts inside it).
constexpr int kCoarseRows = 100000;
std::pair<int, int> CoarseWindow(const Context& cx, const std::vector<int>& chans) {
  if (cx.n <= kCoarseRows) return {0, cx.n};
  std::vector<double> e(static_cast<std::size_t>(cx.n), 0.0);
  for (int i = 1; i < cx.n; ++i) {
    if (!cx.restart.empty() && cx.restart[static_cast<std::size_t>(i)] != 0) continue;
    for (int c : chans) {
      const double s = cx.sim_mvv(i, c) - cx.sim_mvv(i - 1, c);
      e[static_cast<std::size_t>(i)] += s * s * cx.weight(c);
    }
  }
  double run = 0.0;
  for (int i = 0; i < kCoarseRows; ++i) run += e[static_cast<std::size_t>(i)];
  double best = run;
  int best0 = 0;
  for (int i0 = 1; i0 + kCoarseRows <= cx.n; ++i0) {
    run += e[static_cast<std::size_t>(i0 + kCoarseRows - 1)] - e[static_cast<std::size_t>(i0 - 1)];
    if (run > best) {
      best = run;
      best0 = i0;
    }
  }
  return {best0, best0 + kCoarseRows};
}

/// Whitened training SSE of a one-coefficient fit of target to h per channel of `chans`, on rows
/// [w0, w1) (the coarse stage of a windowed ringing search); h(i − w0, k) is channel chans[k].
double WindowSse(const Context& cx, const Series& target, const Mat& h,
                 const std::vector<int>& chans, int w0, int w1) {
  double s = 0.0;
  for (std::size_t k = 0; k < chans.size(); ++k) {
    const int c = chans[k];
    const double* hk = h.col(static_cast<Eigen::Index>(k)).data();
    double hh = 0.0;
    double hy = 0.0;
    double yy = 0.0;
    ForTrainingRows(cx, w0, w1, [&](int i) {
      const double y = target(i, c);
      const double hv = hk[i - w0];
      hh += hv * hv;
      hy += hv * y;
      yy += y * y;
    });
    s += std::max(0.0, yy - (hh > 0 ? hy * hy / hh : 0.0)) * cx.weight(c);
  }
  return s;
}

/// The one-mode ringing at (f, ζ) fitted on every channel and row, streamed (no n × N buffer): the
/// channel fit in *cf, the prediction in *pred; returns the whitened training SSE.
double FitRingingAll(const Context& cx, const Series& target, double f, double z, ChannelFit* cf,
                     Series* pred) {
  ChannelSums sums(cx, 1);
  ForRinging(cx, &f, &z, 1, OnTrainingRows(cx, [&](int i, int c, const double* hv) {
               sums.Add(c, hv, target(i, c));
             }));
  *cf = sums.Solve(cx);
  PredictStreamed(
      cx, *cf, 1, [&](auto visit) { ForRinging(cx, &f, &z, 1, visit); },
      [](int, int, const double* hv, double* x) { x[0] = hv[0]; }, pred);
  return cf->sse_w;
}

/// The one-mode search's objective: the whitened training SSE of the ringing at (f, ζ) on
/// `chans`, on the coarse window's rows (`windowed`) or every row_step-th row. It keeps the ringing
/// only where it reads it (memory: no n × N buffer).
struct OneModeObjective {
  const Context& cx;
  const Series& target;
  int w0 = 0;
  int w1 = 0;
  bool windowed = false;
  int row_step = 1;
  Mat h;

  double operator()(double f, double z, const std::vector<int>& chans) {
    if (!InRange(cx, f, z)) return std::numeric_limits<double>::infinity();
    if (windowed) {
      RingingAt(cx, f, z, chans, w0, w1 - w0, 1, &h);
      return WindowSse(cx, target, h, chans, w0, w1);
    }
    RingingAt(cx, f, z, chans, 0, cx.n, row_step, &h);
    std::vector<int> col(static_cast<std::size_t>(cx.nc), 0);  // channel → column of h
    for (std::size_t k = 0; k < chans.size(); ++k)
      col[static_cast<std::size_t>(chans[k])] = static_cast<int>(k);
    const auto r = FitChannels(
        cx, target, 1,
        [&](int i, int c, double* x) { x[0] = h(i / row_step, col[static_cast<std::size_t>(c)]); },
        nullptr, &chans, row_step);
    double s = 0.0;
    for (int c : chans) s += r.sse(c) * cx.weight(c);
    return s;
  }
};

/// (log f, log ζ) of one mode: the coarse grid (ResonanceGrid × damping ratios from kMinZeta) on
/// the coarse window, or near's optimum; then golden rounds on the coarse channels (a refit only
/// the finer second). False when no point is in range.
bool SearchOneMode(const Context& cx, const Series& target, const EffectFit* near,
                   const std::vector<int>& coarse, OneModeObjective* sse, double* log_fz) {
  const bool warm = near != nullptr && near->search_state.size() >= 2;
  std::vector<double> best = {0.0, 0.0};
  const LogObjective on_coarse = [&](const std::vector<double>& x) {
    return (*sse)(std::exp(x[0]), std::exp(x[1]), coarse);
  };
  double best_sse = std::numeric_limits<double>::infinity();
  if (warm) {
    best = {near->search_state[0], near->search_state[1]};
    if (InRange(cx, std::exp(best[0]), std::exp(best[1]))) best_sse = 0.0;  // no filter pass
  } else {
    std::vector<std::vector<double>> points;
    for (double f : ResonanceGrid(cx, target)) {
      for (double z : {0.001, 0.003, 0.01, 0.03, 0.1, 0.3})
        points.push_back({std::log(f), std::log(z)});
    }
    sse->windowed = sse->w1 - sse->w0 < cx.n;  // the coarse grid and the first round
    best_sse = JointStart(on_coarse, points, &best);
  }
  if (!std::isfinite(best_sse)) return false;
  // A light damping has a narrow optimum in f: the frequency steps shrink with ζ.
  const double f_step = std::clamp(4.0 * std::exp(best[1]), 0.004, 0.04);
  const std::vector<LogBounds> bounds = {{std::log(kMinFreqHz), std::log(MaxFreqHz(cx))},
                                         {std::log(kMinZeta), std::log(kMaxZeta)}};
  // Statuses unused: a mode on a bound is judged by the variant choice (FirstModeOnBound) and by
  // the declared range (NotResolved).
  (void)JointRefine(
      on_coarse, bounds, {f_step, 0.3}, warm ? 1 : 0, 2,
      [&](int round) {
        if (round != 1) return;
        sse->row_step = std::max(1, sse->row_step / 2);
        sse->windowed = false;
      },
      &best);
  log_fz[0] = best[0];
  log_fz[1] = best[1];
  return true;
}

/// The evidence of a finished resonance fit (second: the second mode's words).
std::string RingingEvidence(const Context& cx, const Series& target, const EffectFit& e,
                            const std::string& second) {
  const int c = DominantChannel(cx, e.pred);
  return Fmt("ringing at %.3g Hz (damping ratio %.3g, Q %.0f) after the %d fast load changes on "
             "b%d, quiet during slow ramps and holds, r = %.2f",
             e.params["damped_freq_hz"].get<double>(), e.params["damping_ratio"].get<double>(),
             0.5 / e.params["damping_ratio"].get<double>(), FastLoadChanges(cx, c), c,
             RowCorr(cx, target, e.pred, c)) +
         second;
}

/// Whether a resonance fit's first mode ended within 2 % of its search's bounds.
bool FirstModeOnBound(const Context& cx, const EffectFit& e);

/// The ringing kept between the mode locked to the reference's steps and the one restarted per
/// load change: a per-change fit the engine does not resolve loses to any locked fit, a locked fit
/// whose mode ended on a bound to any per-change fit; else the lower
/// penalised training SSE (BIC: the per-change variant pays for its 2 coefficients per change and
/// channel).
std::optional<EffectFit> BetterRinging(const Context& cx, std::optional<EffectFit> locked,
                                       std::optional<EffectFit> per_change) {
  if (!per_change || (locked && !NotResolved(cx, *per_change).empty())) return locked;
  if (!locked || FirstModeOnBound(cx, *locked)) return per_change;
  const auto bic = [&](const EffectFit& e) { return e.train_sse_w + e.n_params * Penalty(cx); };
  return bic(*per_change) < bic(*locked) ? per_change : locked;
}

}  // namespace

std::optional<EffectFit> ResonanceSearch(const Context& cx, const Series& target,
                                         const EffectFit* near, bool uncertainty) {
  if (near != nullptr && near->variant == kRingingPerChange) {
    return RingingPerChange(cx, target, near, uncertainty);
  }
  auto locked = LockedRingingSearch(cx, target, near, uncertainty);
  if (near != nullptr) return locked;
  return BetterRinging(cx, std::move(locked), RingingPerChange(cx, target, nullptr, uncertainty));
}

std::optional<EffectFit> LockedRingingSearch(const Context& cx, const Series& target,
                                             const EffectFit* near, bool uncertainty) {
  // Coarse search on the two channels with the most residual energy, on all rows or (long records)
  // the window with the most load-step energy; the final fit streams the ringing over every row.
  const std::vector<int> coarse = StrongestTwo(cx, target);
  const auto [w0, w1] = CoarseWindow(cx, coarse);
  OneModeObjective sse{cx, target, w0, w1, false, cx.search_stride, Mat()};
  double log_fz[2] = {0.0, 0.0};
  if (!SearchOneMode(cx, target, near, coarse, &sse, log_fz)) return std::nullopt;
  EffectFit e;
  e.name = "resonance";
  e.n_params = cx.nc + 2;
  ChannelFit cf;
  const double f = std::exp(log_fz[0]);
  const double z = std::exp(log_fz[1]);
  e.train_sse_w = FitRingingAll(cx, target, f, z, &cf, &e.pred);
  e.params["freq_hz"] = f;
  e.params["damping_ratio"] = z;
  e.params["damped_freq_hz"] = f * std::sqrt(std::max(0.0, 1.0 - z * z));
  if (uncertainty) {
    const std::vector<int> all = AllChannels(cx);
    // The curvature step in log f stays inside the optimum's width (about ζ).
    const double step = std::min(0.002, 0.25 * z);
    e.sigma["freq_hz"] = JsonNum(
        f * ProfileSigma([&](double v) { return sse(std::exp(v), z, all); }, log_fz[0], step));
    e.sigma["damping_ratio"] = JsonNum(
        z * ProfileSigma([&](double v) { return sse(f, std::exp(v), all); }, log_fz[1], kOnBound));
  }
  PutChannelCoef(cx, cf, 0, "participation", &e);
  sse.h = Mat();
  e.variant = "one mode";
  e.search_state = {log_fz[0], log_fz[1]};
  const bool near_two = near != nullptr && near->search_state.size() >= 4;
  const std::string second =
      near == nullptr || near_two
          ? AddResonanceMode(cx, target, f, z, &e, near_two ? &near->search_state[2] : nullptr,
                             uncertainty)
          : "";
  e.channels = ActiveChannels(cx, e.pred);
  e.evidence = RingingEvidence(cx, target, e, second);
  return e;
}

namespace {

/// Whether a mode at (log f, log ζ) ended on a bound of its declared range (the engine's rule).
bool OnBound(const Context& cx, double log_f, double log_z) {
  const std::vector<ParamSpec> specs = ResonanceSpecs(cx);
  return StatusOf(specs[0], std::exp(log_f)) != ParamStatus::kResolved ||
         StatusOf(specs[1], std::exp(log_z)) != ParamStatus::kResolved;
}

}  // namespace

namespace {

bool FirstModeOnBound(const Context& cx, const EffectFit& e) {
  return e.search_state.size() >= 2 && OnBound(cx, e.search_state[0], e.search_state[1]);
}

/// Whether two modes are far enough apart to be told apart (more than 15 % in frequency).
bool Apart(double fa_hz, double fb_hz) { return std::fabs(std::log(fa_hz / fb_hz)) > 0.14; }

/// Lines of the residual r (SpectralLines), strongest first, at most 3, none within 15 % of f1_hz.
std::vector<double> ResidualLines(const Context& cx, const Series& r, double f1_hz) {
  std::vector<double> out;
  for (const auto& [level, f_hz] : SpectralLines(cx, r)) {
    if (out.size() < 3 && Apart(f_hz, f1_hz)) out.push_back(f_hz);
  }
  return out;
}

/// Puts both modes' parameters and 1-σ into *e, mode 1 the lower frequency (log f, log ζ and their
/// σ per fitted mode m; participations from column m of cf). Returns the fitted index of mode 2.
int PutModes(const Context& cx, const ChannelFit& cf, const double* log_freq,
             const double* log_zeta, const double* slf, const double* slz, EffectFit* e) {
  const int lo = log_freq[0] <= log_freq[1] ? 0 : 1;
  const char* fkey[2] = {"freq_hz", "freq2_hz"};
  const char* zkey[2] = {"damping_ratio", "damping_ratio2"};
  const char* pkey[2] = {"participation", "participation2"};
  for (int k = 0; k < 2; ++k) {
    const int m = k == 0 ? lo : 1 - lo;
    const double f_hz = std::exp(log_freq[m]);
    const double z = std::exp(log_zeta[m]);
    e->params[fkey[k]] = f_hz;
    e->sigma[fkey[k]] = JsonNum(f_hz * slf[m]);
    e->params[zkey[k]] = z;
    e->sigma[zkey[k]] = JsonNum(z * slz[m]);
    PutChannelCoef(cx, cf, m, pkey[k], e);
  }
  const double z_lo = std::exp(log_zeta[lo]);
  e->params["damped_freq_hz"] =
      std::exp(log_freq[lo]) * std::sqrt(std::max(0.0, 1.0 - z_lo * z_lo));
  return 1 - lo;
}

/// Whether mode (f, ζ) can be searched: in range (InRange) and apart from the other mode at
/// other_hz.
bool ModeInRange(const Context& cx, double f_hz, double zeta, double other_hz) {
  return InRange(cx, f_hz, zeta) && Apart(f_hz, other_hz);
}

/// Each channel's column among `coarse` (0 for a channel not in it).
std::vector<int> ColumnOfChannel(const Context& cx, const std::vector<int>& coarse) {
  std::vector<int> col(static_cast<std::size_t>(cx.nc), 0);
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    col[static_cast<std::size_t>(coarse[k])] = static_cast<int>(k);
  }
  return col;
}

/// The two modes' (log f, log ζ) in log_freq, log_zeta (mode 1 given in log_freq[0], log_zeta[0]):
/// mode 2 on a grid at the residual's `lines` (or from `start`), then golden refinements of each
/// with the other held, on the `coarse` channels. False when no mode 2 is in range.
bool SearchModes(const Context& cx, const Series& target, const std::vector<int>& coarse,
                 const std::vector<double>& lines, const double* start, double* log_freq,
                 double* log_zeta) {
  // The searches keep each mode's ringing only where they read it (every row_step-th row of the
  // coarse channels, compact: RingingAt); the profile curvatures hold the other mode over every row
  // in single precision; the joint fit and the prediction stream both (memory: no n × N double).
  Mat h[2];
  int row_step = cx.search_stride;
  const std::vector<int> col = ColumnOfChannel(cx, coarse);  // channel → column of h[m]
  // Whitened training SSE on the coarse channels with mode m at (f, ζ) and the other mode's
  // ringing held in h[1 − m] (every row_step-th row).
  auto sse = [&](int m, double f_hz, double zeta) {
    if (!ModeInRange(cx, f_hz, zeta, std::exp(log_freq[1 - m])))
      return std::numeric_limits<double>::infinity();
    RingingAt(cx, f_hz, zeta, coarse, 0, cx.n, row_step, &h[m]);
    const ChannelFit r = FitChannels(
        cx, target, 2,
        [&](int i, int c, double* x) {
          const int k = col[static_cast<std::size_t>(c)];
          x[0] = h[0](i / row_step, k);
          x[1] = h[1](i / row_step, k);
        },
        nullptr, &coarse, row_step);
    double s = 0.0;
    for (int c : coarse) s += r.sse(c) * cx.weight(c);
    return s;
  };
  const auto hold = [&](int m) {  // the held mode's ringing at the current stride
    RingingAt(cx, std::exp(log_freq[m]), std::exp(log_zeta[m]), coarse, 0, cx.n, row_step, &h[m]);
  };
  hold(0);
  // Coarse: mode 2 on a grid around each residual line, mode 1 held at its one-mode optimum.
  double best = std::numeric_limits<double>::infinity();
  if (start != nullptr) {
    log_freq[1] = start[0];
    log_zeta[1] = start[1];
    best = sse(1, std::exp(log_freq[1]), std::exp(log_zeta[1]));
  }
  for (double line : lines) {
    for (double m : {0.92, 1.0, 1.08}) {
      for (double z : {0.01, 0.03, 0.1, 0.3}) {
        const double s = sse(1, line * m, z);
        if (s < best) {
          best = s;
          log_freq[1] = std::log(line * m);
          log_zeta[1] = std::log(z);
        }
      }
    }
  }
  if (!std::isfinite(best)) return false;
  // Golden refinements of log f and log ζ of mode 2, then mode 1 (the other held): twice, or once
  // (the finer round) from a refit's start.
  for (int round = start != nullptr ? 1 : 0; round < 2; ++round) {
    if (round == 1) row_step = std::max(1, row_step / 2);
    for (int m : {1, 0}) {
      hold(1 - m);
      std::vector<double> g1;
      std::vector<double> g2;
      for (int j = -2; j <= 2; ++j) {
        g1.push_back(log_freq[m] + 0.04 * j / (round + 1));
        g2.push_back(log_zeta[m] + 0.3 * j / (round + 1));
      }
      const std::vector<ParamSpec> specs = ResonanceSpecs(cx);
      log_freq[m] =
          SolveParameter(
              specs[2 * m], [&](double v) { return sse(m, std::exp(v), std::exp(log_zeta[m])); },
              GridOnly(g1, 7))
              .coord;
      log_zeta[m] =
          SolveParameter(
              specs[2 * m + 1],
              [&](double v) { return sse(m, std::exp(log_freq[m]), std::exp(v)); }, GridOnly(g2, 7))
              .coord;
    }
  }
  return true;
}

/// 1-σ of each mode's log f and log ζ (slf, slz) from the profile curvature of the whitened
/// training SSE on every channel and row, the other mode held at its optimum.
void ModeCurvatures(const Context& cx, const Series& target, const double* log_freq,
                    const double* log_zeta, double* slf, double* slz) {
  for (int m : {0, 1}) {
    Series held(cx.n, cx.nc);
    const double f_held = std::exp(log_freq[1 - m]);
    const double z_held = std::exp(log_zeta[1 - m]);
    ForRinging(cx, &f_held, &z_held, 1,
               [&](int i, int c, const double* hv) { held(i, c) = static_cast<float>(hv[0]); });
    auto sse_all = [&](double f_hz, double zeta) {
      if (!ModeInRange(cx, f_hz, zeta, f_held)) return std::numeric_limits<double>::infinity();
      ChannelSums sums(cx, 2);
      ForRinging(cx, &f_hz, &zeta, 1, OnTrainingRows(cx, [&](int i, int c, const double* hv) {
                   const double other = held(i, c);
                   const double x[2] = {m == 0 ? hv[0] : other, m == 0 ? other : hv[0]};
                   sums.Add(c, x, target(i, c));
                 }));
      return sums.Solve(cx).sse_w;
    };
    slf[m] = ProfileSigma([&](double v) { return sse_all(std::exp(v), std::exp(log_zeta[m])); },
                          log_freq[m], 0.002);
    slz[m] = ProfileSigma([&](double v) { return sse_all(std::exp(log_freq[m]), std::exp(v)); },
                          log_zeta[m], kOnBound);
  }
}

}  // namespace

std::string AddResonanceMode(const Context& cx, const Series& target, double f1_hz, double zeta1,
                             EffectFit* e, const double* start, bool uncertainty) {
  std::vector<double> lines;  // the residual's lines (none needed from a refit's start)
  std::vector<int> coarse;
  {
    const Series resid = target - e->pred;  // memory: released before the ringing buffers
    if (start == nullptr && (lines = ResidualLines(cx, resid, f1_hz)).empty()) return "";
    coarse = StrongestTwo(cx, resid);
  }
  double log_freq[2] = {std::log(f1_hz), 0.0};
  double log_zeta[2] = {std::log(zeta1), 0.0};
  if (!SearchModes(cx, target, coarse, lines, start, log_freq, log_zeta)) return "";
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double slf[2] = {kNaN, kNaN};
  double slz[2] = {kNaN, kNaN};
  if (uncertainty) ModeCurvatures(cx, target, log_freq, log_zeta, slf, slz);
  // The joint fit and each mode's whitened energy on the training rows, streamed.
  const double f12[2] = {std::exp(log_freq[0]), std::exp(log_freq[1])};
  const double z12[2] = {std::exp(log_zeta[0]), std::exp(log_zeta[1])};
  ChannelSums sums(cx, 2);
  Mat hh = Mat::Zero(2, cx.nc);  // Σ h_j² over the training rows per channel
  ForRinging(cx, f12, z12, 2, OnTrainingRows(cx, [&](int i, int c, const double* hv) {
               sums.Add(c, hv, target(i, c));
               hh(0, c) += hv[0] * hv[0];
               hh(1, c) += hv[1] * hv[1];
             }));
  const ChannelFit cf = sums.Solve(cx);
  const auto mode_energy = [&](int j) {  // whitened energy of β_j·h_j, summed over channels
    double energy = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      energy += hh(j, c) * cf.beta(j, c) * cf.beta(j, c) * cx.weight(c);
    }
    return energy;
  };
  const int p = 2 * cx.nc + 4;
  const double gain = e->train_sse_w + e->n_params * Penalty(cx) - (cf.sse_w + p * Penalty(cx));
  const double e1 = mode_energy(0);
  const double e2 = mode_energy(1);
  const double share = std::min(e1, e2) / std::max(e1 + e2, 1e-300);
  const double f2_hz = std::exp(log_freq[1]);
  // Materiality: the weaker mode must carry ≥ 1 % of the ringing's whitened energy (10 % of its
  // amplitude), else a small mismatch of one mode would be named a second one.
  if (gain <= 0.0 || share < 0.01 || OnBound(cx, log_freq[0], log_zeta[0]) ||
      OnBound(cx, log_freq[1], log_zeta[1])) {
    return Fmt(
        "; a second mode near %.2f Hz was tried and not kept (training BIC %+.1f, share %.1f "
        "%% of the ringing, damping ratio %.3g)",
        f2_hz, gain, 100.0 * share, std::exp(log_zeta[1]));
  }
  const int hi = PutModes(cx, cf, log_freq, log_zeta, slf, slz, e);
  e->variant = "two modes";
  e->n_params = p;
  e->train_sse_w = cf.sse_w;
  e->pred = Series();  // the one-mode prediction is replaced
  PredictStreamed(
      cx, cf, 2, [&](auto visit) { ForRinging(cx, f12, z12, 2, visit); },
      [](int, int, const double* hv, double* x) {
        x[0] = hv[0];
        x[1] = hv[1];
      },
      &e->pred);
  e->search_state = {log_freq[0], log_zeta[0], log_freq[1], log_zeta[1]};
  return Fmt(
      "; a second mode at %.2f Hz (damping ratio %.3f) from the residual spectrum, kept: "
      "training BIC lower by %.1f, %.0f %% of the ringing's energy in the weaker mode",
      std::exp(log_freq[hi]), std::exp(log_zeta[hi]), gain, 100.0 * share);
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ResonancePlugin() {
  return {.kind = EffectKind::kResonance,
          .fit = &fx::FitBy<&fx::ResonanceSearch>,
          .refit = &fx::RefitBy<&fx::ResonanceSearch>,
          .cost = 8,
          .ranges = &fx::ResonanceSpecs,
          .fit_ranges = &fx::ResonanceFitSpecs};
}

}  // namespace ftstack::diag
