// Timing and dynamics: time_skew, mains_interference, resonance.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitTimeSkew(const Context& cx, const Series& target) {
  const auto& d = *cx.data;
  auto predict = [&](double delay, Series* out) {
    double sse = 0.0;
    const int st = out == nullptr ? cx.search_stride : 1;
    for (int c = 0; c < cx.nc; ++c) {
      const double* s = cx.load.col(c).data();  // load = sim − zero: the same differences
      double acc = 0.0;
      for (int i = 0; i < cx.n; i += st) {
        const bool tr = cx.train[static_cast<std::size_t>(i)] != 0;
        if (!tr && out == nullptr) continue;
        const double v = InterpolateNear(d.t_s.data(), s, static_cast<std::size_t>(cx.n),
                                         d.t_s[static_cast<std::size_t>(i)] - delay, cx.uniform,
                                         static_cast<std::size_t>(i)) -
                         s[i];
        if (out != nullptr) (*out)(i, c) = static_cast<float>(v);
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
          (cx.sim_mvv(i + 1, c) - cx.sim_mvv(i - 1, c)) /
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

std::optional<EffectFit> FitMains(const Context& cx, const Series& target) {
  if (cx.peak_hz.empty()) return std::nullopt;
  const auto& d = *cx.data;
  // cos and sin of the phase once per row for every channel (the same values FitChannels would
  // otherwise compute per row and channel).
  std::vector<double> cs(static_cast<std::size_t>(cx.n));
  std::vector<double> sn(static_cast<std::size_t>(cx.n));
  auto fit_at = [&](double f, Series* out, ChannelFit* cf) {
    const double w = 2.0 * M_PI * f;
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const double ph = w * d.t_s[i];
      cs[i] = std::cos(ph);
      sn[i] = std::sin(ph);
    }
    auto r = FitChannels(
        cx, target, 2,
        [&](int i, int, double* x) {
          x[0] = cs[static_cast<std::size_t>(i)];
          x[1] = sn[static_cast<std::size_t>(i)];
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
  e.variant = "mains fundamental";
  const std::string harmonics = AddMainsHarmonics(cx, target, best_f, &e);
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence = Fmt("a steady line at %.3f Hz on %s, %.3g mV/V (%.1f σ) on b%d, present at every "
                   "load and time",
                   best_f, ChannelList(e.channels).c_str(), amp(c), amp(c) / cx.sigma(c), c) +
               harmonics;
  return e;
}

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
  // The searches keep the ringing only where they read it (the window's rows, or every st-th row,
  // of their channels); the final fit streams it over every row (memory: no n × N buffer).
  Mat h;
  // Coarse search on the two channels with the most residual energy, on all rows or (long records)
  // the window with the most load-step energy.
  const std::vector<int> coarse = StrongestTwo(cx, target);
  const auto [w0, w1] = CoarseWindow(cx, coarse);
  bool windowed = false;
  int st = cx.search_stride;
  const auto in_range = [&](double f, double z) {
    return f > 0.05 && f < 0.98 * nyq && z > 1e-4 && z <= 2.0;
  };
  auto sse_for = [&](double f, double z, const std::vector<int>& chans) {
    if (!in_range(f, z)) return std::numeric_limits<double>::infinity();
    if (windowed) {
      RingingAt(cx, f, z, chans, w0, w1 - w0, 1, &h);
      return WindowSse(cx, target, h, chans, w0, w1);
    }
    RingingAt(cx, f, z, chans, 0, cx.n, st, &h);
    std::vector<int> col(static_cast<std::size_t>(cx.nc), 0);  // channel → column of h
    for (std::size_t k = 0; k < chans.size(); ++k)
      col[static_cast<std::size_t>(chans[k])] = static_cast<int>(k);
    const auto r = FitChannels(
        cx, target, 1,
        [&](int i, int c, double* x) { x[0] = h(i / st, col[static_cast<std::size_t>(c)]); },
        nullptr, &chans, st);
    double s = 0.0;
    for (int c : chans) s += r.sse(c) * cx.weight(c);
    return s;
  };
  const std::vector<int> all = AllChannels(cx);
  std::vector<double> fgrid = ResonanceGrid(cx);
  const double zgrid[] = {0.01, 0.03, 0.1, 0.3};
  double bf = 0.0;
  double bz = 0.0;
  double bs = std::numeric_limits<double>::infinity();
  const bool warm = near != nullptr && near->search_state.size() >= 2;
  if (warm) {
    bf = std::exp(near->search_state[0]);
    bz = std::exp(near->search_state[1]);
    if (in_range(bf, bz)) bs = 0.0;  // only its finiteness is used below: no filter pass needed
    fgrid.clear();
  }
  windowed = w1 - w0 < cx.n;  // the coarse grid and the first round
  for (double f : fgrid) {
    for (double z : zgrid) {
      const double s = sse_for(f, z, coarse);
      if (s < bs) {
        bs = s;
        bf = f;
        bz = z;
      }
    }
  }
  if (!std::isfinite(bs)) return std::nullopt;
  // Alternate golden refinements in log f and log ζ on the coarse channels (a refit starts near
  // its optimum: only the finer second round).
  double lf = std::log(bf);
  double lz = std::log(bz);
  for (int round = warm ? 1 : 0; round < 2; ++round) {
    const std::vector<int>& chans = coarse;  // all channels only in the final fit
    if (round == 1) {
      st = std::max(1, st / 2);
      windowed = false;
    }
    std::vector<double> g1;
    for (int j = -2; j <= 2; ++j) g1.push_back(lf + 0.04 * j / (round + 1));
    lf = MinimizeOnGrid([&](double v) { return sse_for(std::exp(v), std::exp(lz), chans); }, g1, 7,
                        nullptr);
    std::vector<double> g2;
    for (int j = -2; j <= 2; ++j) g2.push_back(lz + 0.3 * j / (round + 1));
    lz = MinimizeOnGrid([&](double v) { return sse_for(std::exp(lf), std::exp(v), chans); }, g2, 7,
                        nullptr);
  }
  EffectFit e;
  e.name = "resonance";
  e.n_params = cx.nc + 2;
  ChannelFit cf;
  const double f = std::exp(lf);
  const double z = std::exp(lz);
  e.train_sse_w = FitRingingAll(cx, target, f, z, &cf, &e.pred);
  e.params["freq_hz"] = f;
  e.params["damping_ratio"] = z;
  e.params["damped_freq_hz"] = f * std::sqrt(std::max(0.0, 1.0 - z * z));
  if (uncertainty) {
    e.sigma["freq_hz"] = JsonNum(
        f * CurvatureSigma([&](double v) { return sse_for(std::exp(v), z, all); }, lf, 0.002));
    e.sigma["damping_ratio"] = JsonNum(
        z * CurvatureSigma([&](double v) { return sse_for(f, std::exp(v), all); }, lz, 0.02));
  }
  PutChannelCoef(cx, cf, 0, "participation", &e);
  h = Mat();
  e.variant = "one mode";
  e.search_state = {lf, lz};
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

}  // namespace ftstack::diag::fx
