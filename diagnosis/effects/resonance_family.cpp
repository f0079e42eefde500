// resonance family: a second mode, searched at the lines of the one-mode fit's residual spectrum
// and fitted jointly with the first, kept only when the training BIC says so.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag::fx {
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
int PutModes(const Context& cx, const ChannelFit& cf, const double* lf, const double* lz,
             const double* slf, const double* slz, EffectFit* e) {
  const int lo = lf[0] <= lf[1] ? 0 : 1;
  const char* fkey[2] = {"freq_hz", "freq2_hz"};
  const char* zkey[2] = {"damping_ratio", "damping_ratio2"};
  const char* pkey[2] = {"participation", "participation2"};
  for (int k = 0; k < 2; ++k) {
    const int m = k == 0 ? lo : 1 - lo;
    const double f_hz = std::exp(lf[m]);
    const double z = std::exp(lz[m]);
    e->params[fkey[k]] = f_hz;
    e->sigma[fkey[k]] = JsonNum(f_hz * slf[m]);
    e->params[zkey[k]] = z;
    e->sigma[zkey[k]] = JsonNum(z * slz[m]);
    PutChannelCoef(cx, cf, m, pkey[k], e);
  }
  const double z_lo = std::exp(lz[lo]);
  e->params["damped_freq_hz"] = std::exp(lf[lo]) * std::sqrt(std::max(0.0, 1.0 - z_lo * z_lo));
  return 1 - lo;
}

/// Whether mode (f, ζ) can be searched: below 0.98 × Nyquist, ζ in (1e-4, 2] and apart from the
/// other mode at other_hz.
bool ModeInRange(const Context& cx, double f_hz, double zeta, double other_hz) {
  return f_hz > 0.05 && f_hz < 0.98 * 0.5 * cx.rate_hz && zeta > 1e-4 && zeta <= 2.0 &&
         Apart(f_hz, other_hz);
}

/// The two modes' (log f, log ζ) in lf, lz (mode 1 given in lf[0], lz[0]): mode 2 on a grid at the
/// residual's `lines` (or from `start`), then golden refinements of each with the other held, on
/// the `coarse` channels. False when no mode 2 is in range.
bool SearchModes(const Context& cx, const Series& target, const std::vector<int>& coarse,
                 const std::vector<double>& lines, const double* start, double* lf, double* lz) {
  // The searches keep each mode's ringing only where they read it (every st-th row of the coarse
  // channels, compact: RingingAt); the profile curvatures hold the other mode over every row in
  // single precision; the joint fit and the prediction stream both (memory: no n × N double).
  Mat h[2];
  int st = cx.search_stride;
  std::vector<int> col(static_cast<std::size_t>(cx.nc), 0);  // channel → column of h[m]
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    col[static_cast<std::size_t>(coarse[k])] = static_cast<int>(k);
  }
  // Whitened training SSE on the coarse channels with mode m at (f, ζ) and the other mode's
  // ringing held in h[1 − m] (every st-th row).
  auto sse = [&](int m, double f_hz, double zeta) {
    if (!ModeInRange(cx, f_hz, zeta, std::exp(lf[1 - m])))
      return std::numeric_limits<double>::infinity();
    RingingAt(cx, f_hz, zeta, coarse, 0, cx.n, st, &h[m]);
    const ChannelFit r = FitChannels(
        cx, target, 2,
        [&](int i, int c, double* x) {
          const int k = col[static_cast<std::size_t>(c)];
          x[0] = h[0](i / st, k);
          x[1] = h[1](i / st, k);
        },
        nullptr, &coarse, st);
    double s = 0.0;
    for (int c : coarse) s += r.sse(c) * cx.weight(c);
    return s;
  };
  const auto hold = [&](int m) {  // the held mode's ringing at the current stride
    RingingAt(cx, std::exp(lf[m]), std::exp(lz[m]), coarse, 0, cx.n, st, &h[m]);
  };
  hold(0);
  // Coarse: mode 2 on a grid around each residual line, mode 1 held at its one-mode optimum.
  double best = std::numeric_limits<double>::infinity();
  if (start != nullptr) {
    lf[1] = start[0];
    lz[1] = start[1];
    best = sse(1, std::exp(lf[1]), std::exp(lz[1]));
  }
  for (double line : lines) {
    for (double m : {0.92, 1.0, 1.08}) {
      for (double z : {0.01, 0.03, 0.1, 0.3}) {
        const double s = sse(1, line * m, z);
        if (s < best) {
          best = s;
          lf[1] = std::log(line * m);
          lz[1] = std::log(z);
        }
      }
    }
  }
  if (!std::isfinite(best)) return false;
  // Golden refinements of log f and log ζ of mode 2, then mode 1 (the other held): twice, or once
  // (the finer round) from a refit's start.
  for (int round = start != nullptr ? 1 : 0; round < 2; ++round) {
    if (round == 1) st = std::max(1, st / 2);
    for (int m : {1, 0}) {
      hold(1 - m);
      std::vector<double> g1;
      std::vector<double> g2;
      for (int j = -2; j <= 2; ++j) {
        g1.push_back(lf[m] + 0.04 * j / (round + 1));
        g2.push_back(lz[m] + 0.3 * j / (round + 1));
      }
      lf[m] = MinimizeOnGrid([&](double v) { return sse(m, std::exp(v), std::exp(lz[m])); }, g1, 7,
                             nullptr);
      lz[m] = MinimizeOnGrid([&](double v) { return sse(m, std::exp(lf[m]), std::exp(v)); }, g2, 7,
                             nullptr);
    }
  }
  return true;
}

/// 1-σ of each mode's log f and log ζ (slf, slz) from the profile curvature of the whitened
/// training SSE on every channel and row, the other mode held at its optimum.
void ModeCurvatures(const Context& cx, const Series& target, const double* lf, const double* lz,
                    double* slf, double* slz) {
  for (int m : {0, 1}) {
    Series held(cx.n, cx.nc);
    const double f_held = std::exp(lf[1 - m]);
    const double z_held = std::exp(lz[1 - m]);
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
    slf[m] = CurvatureSigma([&](double v) { return sse_all(std::exp(v), std::exp(lz[m])); }, lf[m],
                            0.002);
    slz[m] = CurvatureSigma([&](double v) { return sse_all(std::exp(lf[m]), std::exp(v)); }, lz[m],
                            0.02);
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
  double lf[2] = {std::log(f1_hz), 0.0};
  double lz[2] = {std::log(zeta1), 0.0};
  if (!SearchModes(cx, target, coarse, lines, start, lf, lz)) return "";
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double slf[2] = {kNaN, kNaN};
  double slz[2] = {kNaN, kNaN};
  if (uncertainty) ModeCurvatures(cx, target, lf, lz, slf, slz);
  // The joint fit and each mode's whitened energy on the training rows, streamed.
  const double f12[2] = {std::exp(lf[0]), std::exp(lf[1])};
  const double z12[2] = {std::exp(lz[0]), std::exp(lz[1])};
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
  const double f2_hz = std::exp(lf[1]);
  // Materiality: the weaker mode must carry ≥ 1 % of the ringing's whitened energy (10 % of its
  // amplitude), else a small mismatch of one mode would be named a second one.
  if (gain <= 0.0 || share < 0.01) {
    return Fmt(
        "; a second mode near %.2f Hz was tried and not kept (training BIC %+.1f, share %.1f "
        "%% of the ringing)",
        f2_hz, gain, 100.0 * share);
  }
  const int hi = PutModes(cx, cf, lf, lz, slf, slz, e);
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
  e->search_state = {lf[0], lz[0], lf[1], lz[1]};
  return Fmt(
      "; a second mode at %.2f Hz (damping ratio %.3f) from the residual spectrum, kept: "
      "training BIC lower by %.1f, %.0f %% of the ringing's energy in the weaker mode",
      std::exp(lf[hi]), std::exp(lz[hi]), gain, 100.0 * share);
}

}  // namespace ftstack::diag::fx
