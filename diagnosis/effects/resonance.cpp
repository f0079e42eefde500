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
#include "diagnosis/engine/signal.hpp"

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

/// The coarse frequency grid: ±8 % around each of the 3 strongest lines of the residual spectrum,
/// or 12 log-spaced points from 1 Hz to 0.9 × Nyquist without any.
std::vector<double> ResonanceGrid(const Context& cx) {
  std::vector<double> fgrid;
  for (std::size_t p = 0; p < std::min<std::size_t>(cx.peak_hz.size(), 3); ++p) {
    for (double m : {0.92, 1.0, 1.08}) fgrid.push_back(cx.peak_hz[p] * m);
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
    for (int i = w0; i < w1; ++i) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      const double y = target(i, c);
      const double hv = hk[i - w0];
      hh += hv * hv;
      hy += hv * y;
      yy += y * y;
    }
    s += std::max(0.0, yy - (hh > 0 ? hy * hy / hh : 0.0)) * cx.weight(c);
  }
  return s;
}

/// The one-mode ringing at (f, ζ) fitted on every channel and row, streamed (no n × N buffer): the
/// channel fit in *cf, the prediction in *pred; returns the whitened training SSE.
double FitRingingAll(const Context& cx, const Series& target, double f, double z, ChannelFit* cf,
                     Series* pred) {
  ChannelSums sums(cx, 1);
  ForRinging(cx, &f, &z, 1, [&](int i, int c, const double* hv) {
    if (cx.train[static_cast<std::size_t>(i)]) sums.Add(c, hv, target(i, c));
  });
  *cf = sums.Solve(cx);
  PredictStreamed(
      cx, *cf, 1, [&](auto visit) { ForRinging(cx, &f, &z, 1, visit); },
      [](int, int, const double* hv, double* x) { x[0] = hv[0]; }, pred);
  return cf->sse_w;
}

}  // namespace

std::optional<EffectFit> ResonanceSearch(const Context& cx, const Series& target,
                                         const EffectFit* near, bool uncertainty) {
  const double nyq = 0.5 * cx.rate_hz;
  // The searches keep the ringing only where they read it (the window's rows, or every row_step-th
  // row, of their channels); the final fit streams it over every row (memory: no n × N buffer).
  Mat h;
  // Coarse search on the two channels with the most residual energy, on all rows or (long records)
  // the window with the most load-step energy.
  const std::vector<int> coarse = StrongestTwo(cx, target);
  const auto [w0, w1] = CoarseWindow(cx, coarse);
  bool windowed = false;
  int row_step = cx.search_stride;
  const auto in_range = [&](double f, double z) {
    return f > 0.05 && f < 0.98 * nyq && z > 1e-4 && z <= 2.0;
  };
  auto sse_for = [&](double f, double z, const std::vector<int>& chans) {
    if (!in_range(f, z)) return std::numeric_limits<double>::infinity();
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
  };
  const std::vector<int> all = AllChannels(cx);
  std::vector<double> fgrid = ResonanceGrid(cx);
  const double zgrid[] = {0.01, 0.03, 0.1, 0.3};
  double best_freq = 0.0;
  double best_zeta = 0.0;
  double best_sse = std::numeric_limits<double>::infinity();
  const bool warm = near != nullptr && near->search_state.size() >= 2;
  if (warm) {
    best_freq = std::exp(near->search_state[0]);
    best_zeta = std::exp(near->search_state[1]);
    if (in_range(best_freq, best_zeta))
      best_sse = 0.0;  // only its finiteness is used below: no filter pass needed
    fgrid.clear();
  }
  windowed = w1 - w0 < cx.n;  // the coarse grid and the first round
  for (double f : fgrid) {
    for (double z : zgrid) {
      const double s = sse_for(f, z, coarse);
      if (s < best_sse) {
        best_sse = s;
        best_freq = f;
        best_zeta = z;
      }
    }
  }
  if (!std::isfinite(best_sse)) return std::nullopt;
  // Alternate golden refinements in log f and log ζ on the coarse channels (a refit starts near
  // its optimum: only the finer second round).
  double log_freq = std::log(best_freq);
  double log_zeta = std::log(best_zeta);
  for (int round = warm ? 1 : 0; round < 2; ++round) {
    const std::vector<int>& chans = coarse;  // all channels only in the final fit
    if (round == 1) {
      row_step = std::max(1, row_step / 2);
      windowed = false;
    }
    std::vector<double> g1;
    for (int j = -2; j <= 2; ++j) g1.push_back(log_freq + 0.04 * j / (round + 1));
    log_freq = MinimizeOnGrid(
        [&](double v) { return sse_for(std::exp(v), std::exp(log_zeta), chans); }, g1, 7, nullptr);
    std::vector<double> g2;
    for (int j = -2; j <= 2; ++j) g2.push_back(log_zeta + 0.3 * j / (round + 1));
    log_zeta = MinimizeOnGrid(
        [&](double v) { return sse_for(std::exp(log_freq), std::exp(v), chans); }, g2, 7, nullptr);
  }
  EffectFit e;
  e.name = "resonance";
  e.n_params = cx.nc + 2;
  ChannelFit cf;
  const double f = std::exp(log_freq);
  const double z = std::exp(log_zeta);
  e.train_sse_w = FitRingingAll(cx, target, f, z, &cf, &e.pred);
  e.params["freq_hz"] = f;
  e.params["damping_ratio"] = z;
  e.params["damped_freq_hz"] = f * std::sqrt(std::max(0.0, 1.0 - z * z));
  if (uncertainty) {
    e.sigma["freq_hz"] =
        JsonNum(f * CurvatureSigma([&](double v) { return sse_for(std::exp(v), z, all); }, log_freq,
                                   0.002));
    e.sigma["damping_ratio"] = JsonNum(
        z * CurvatureSigma([&](double v) { return sse_for(f, std::exp(v), all); }, log_zeta, 0.02));
  }
  PutChannelCoef(cx, cf, 0, "participation", &e);
  h = Mat();
  e.variant = "one mode";
  e.search_state = {log_freq, log_zeta};
  const bool near_two = warm && near->search_state.size() >= 4;
  const std::string second =
      near == nullptr || near_two
          ? AddResonanceMode(cx, target, f, z, &e, near_two ? &near->search_state[2] : nullptr,
                             uncertainty)
          : "";
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  const int fast = FastLoadChanges(cx, c);
  e.evidence =
      Fmt("ringing at %.2f Hz (damping ratio %.3f) after the %d fast load changes on b%d, quiet "
          "during slow ramps and holds, r = %.2f",
          e.params["damped_freq_hz"].get<double>(), e.params["damping_ratio"].get<double>(), fast,
          c, RowCorr(cx, target, e.pred, c)) +
      second;
  return e;
}

namespace {

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

/// Whether mode (f, ζ) can be searched: below 0.98 × Nyquist, ζ in (1e-4, 2] and apart from the
/// other mode at other_hz.
bool ModeInRange(const Context& cx, double f_hz, double zeta, double other_hz) {
  return f_hz > 0.05 && f_hz < 0.98 * 0.5 * cx.rate_hz && zeta > 1e-4 && zeta <= 2.0 &&
         Apart(f_hz, other_hz);
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
  std::vector<int> col(static_cast<std::size_t>(cx.nc), 0);  // channel → column of h[m]
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    col[static_cast<std::size_t>(coarse[k])] = static_cast<int>(k);
  }
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
      log_freq[m] = MinimizeOnGrid(
          [&](double v) { return sse(m, std::exp(v), std::exp(log_zeta[m])); }, g1, 7, nullptr);
      log_zeta[m] = MinimizeOnGrid(
          [&](double v) { return sse(m, std::exp(log_freq[m]), std::exp(v)); }, g2, 7, nullptr);
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
      ForRinging(cx, &f_hz, &zeta, 1, [&](int i, int c, const double* hv) {
        if (!cx.train[static_cast<std::size_t>(i)]) return;
        const double other = held(i, c);
        const double x[2] = {m == 0 ? hv[0] : other, m == 0 ? other : hv[0]};
        sums.Add(c, x, target(i, c));
      });
      return sums.Solve(cx).sse_w;
    };
    slf[m] = CurvatureSigma([&](double v) { return sse_all(std::exp(v), std::exp(log_zeta[m])); },
                            log_freq[m], 0.002);
    slz[m] = CurvatureSigma([&](double v) { return sse_all(std::exp(log_freq[m]), std::exp(v)); },
                            log_zeta[m], 0.02);
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
  ForRinging(cx, f12, z12, 2, [&](int i, int c, const double* hv) {
    if (!cx.train[static_cast<std::size_t>(i)]) return;
    sums.Add(c, hv, target(i, c));
    hh(0, c) += hv[0] * hv[0];
    hh(1, c) += hv[1] * hv[1];
  });
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
  if (gain <= 0.0 || share < 0.01) {
    return Fmt(
        "; a second mode near %.2f Hz was tried and not kept (training BIC %+.1f, share %.1f "
        "%% of the ringing)",
        f2_hz, gain, 100.0 * share);
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
          .cost = 8};
}

}  // namespace ftstack::diag
