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

/// h(·, c) = H_{f,ζ}[sim_c] − sim_c on the channels `chans`: the exact second-order low pass on the
/// actual dt of every row, restarting at rest at every segment.
void Ringing(const Context& cx, double f_hz, double zeta, const std::vector<int>& chans, Mat* h) {
  RingingRows(cx, f_hz, zeta, chans, 0, cx.n, h);
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

/// Whitened energy of β_j·h over the training rows, summed over channels.
double ModeEnergy(const Context& cx, const ChannelFit& f, int j, const Mat& h) {
  double e = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    double s = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      if (cx.train[static_cast<std::size_t>(i)]) s += h(i, c) * h(i, c);
    }
    e += s * f.beta(j, c) * f.beta(j, c) * cx.weight(c);
  }
  return e;
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

}  // namespace

std::string AddResonanceMode(const Context& cx, const Series& target, double f1_hz, double zeta1,
                             EffectFit* e, const double* start, bool uncertainty) {
  const double nyq_hz = 0.5 * cx.rate_hz;
  std::vector<double> lines;  // the residual's lines (none needed from a refit's start)
  std::vector<int> coarse;
  {
    const Series resid = target - e->pred;  // memory: released before the ringing buffers
    if (start == nullptr && (lines = ResidualLines(cx, resid, f1_hz)).empty()) return "";
    coarse = StrongestTwo(cx, resid);
  }
  const std::vector<int> all = AllChannels(cx);
  Mat h1(cx.n, cx.nc);
  Mat h2(cx.n, cx.nc);
  double lf[2] = {std::log(f1_hz), 0.0};
  double lz[2] = {std::log(zeta1), 0.0};
  Mat* h[2] = {&h1, &h2};
  const auto modes = [&](int i, int c, double* x) {  // both modes' ringing
    x[0] = h1(i, c);
    x[1] = h2(i, c);
  };
  auto fit = [&](const std::vector<int>& chans, Series* pred, int stride) {
    return FitChannels(cx, target, 2, modes, pred, &chans, stride);
  };
  // Whitened training SSE with mode m at (f, ζ) and the other mode's ringing held.
  auto sse = [&](int m, double f_hz, double zeta, const std::vector<int>& chans, int stride) {
    if (f_hz <= 0.05 || f_hz >= 0.98 * nyq_hz || zeta <= 1e-4 || zeta > 2.0 ||
        !Apart(f_hz, std::exp(lf[1 - m]))) {
      return std::numeric_limits<double>::infinity();
    }
    Ringing(cx, f_hz, zeta, chans, h[m]);
    const ChannelFit r = fit(chans, nullptr, stride);
    double s = 0.0;
    for (int c : chans) s += r.sse(c) * cx.weight(c);
    return s;
  };
  Ringing(cx, f1_hz, zeta1, all, &h1);
  // Coarse: mode 2 on a grid around each residual line, mode 1 held at its one-mode optimum.
  int st = cx.search_stride;
  double best = std::numeric_limits<double>::infinity();
  if (start != nullptr) {
    lf[1] = start[0];
    lz[1] = start[1];
    best = sse(1, std::exp(lf[1]), std::exp(lz[1]), coarse, st);
  }
  for (double line : lines) {
    for (double m : {0.92, 1.0, 1.08}) {
      for (double z : {0.01, 0.03, 0.1, 0.3}) {
        const double s = sse(1, line * m, z, coarse, st);
        if (s < best) {
          best = s;
          lf[1] = std::log(line * m);
          lz[1] = std::log(z);
        }
      }
    }
  }
  if (!std::isfinite(best)) return "";
  // Golden refinements of log f and log ζ of mode 2, then mode 1 (the other held): twice, or once
  // (the finer round) from a refit's start.
  for (int round = start != nullptr ? 1 : 0; round < 2; ++round) {
    if (round == 1) st = std::max(1, st / 2);
    for (int m : {1, 0}) {
      Ringing(cx, std::exp(lf[1 - m]), std::exp(lz[1 - m]), coarse, h[1 - m]);
      std::vector<double> g1;
      std::vector<double> g2;
      for (int j = -2; j <= 2; ++j) {
        g1.push_back(lf[m] + 0.04 * j / (round + 1));
        g2.push_back(lz[m] + 0.3 * j / (round + 1));
      }
      lf[m] =
          MinimizeOnGrid([&](double v) { return sse(m, std::exp(v), std::exp(lz[m]), coarse, st); },
                         g1, 7, nullptr);
      lz[m] =
          MinimizeOnGrid([&](double v) { return sse(m, std::exp(lf[m]), std::exp(v), coarse, st); },
                         g2, 7, nullptr);
    }
  }
  // Profile curvatures on every channel and row (the other mode held at its optimum).
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double slf[2] = {kNaN, kNaN};
  double slz[2] = {kNaN, kNaN};
  for (int m : {0, 1}) {
    if (!uncertainty) break;
    Ringing(cx, std::exp(lf[1 - m]), std::exp(lz[1 - m]), all, h[1 - m]);
    slf[m] = CurvatureSigma([&](double v) { return sse(m, std::exp(v), std::exp(lz[m]), all, 1); },
                            lf[m], 0.002);
    slz[m] = CurvatureSigma([&](double v) { return sse(m, std::exp(lf[m]), std::exp(v), all, 1); },
                            lz[m], 0.02);
  }
  Ringing(cx, std::exp(lf[0]), std::exp(lz[0]), all, &h1);
  Ringing(cx, std::exp(lf[1]), std::exp(lz[1]), all, &h2);
  const ChannelFit cf = fit(all, nullptr, 1);  // the prediction only if kept (memory, below)
  const int p = 2 * cx.nc + 4;
  const double gain = e->train_sse_w + e->n_params * Penalty(cx) - (cf.sse_w + p * Penalty(cx));
  const double e1 = ModeEnergy(cx, cf, 0, h1);
  const double e2 = ModeEnergy(cx, cf, 1, h2);
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
  PredictChannels(cx, cf, 2, modes, &e->pred);
  e->search_state = {lf[0], lz[0], lf[1], lz[1]};
  return Fmt(
      "; a second mode at %.2f Hz (damping ratio %.3f) from the residual spectrum, kept: "
      "training BIC lower by %.1f, %.0f %% of the ringing's energy in the weaker mode",
      std::exp(lf[hi]), std::exp(lz[hi]), gain, 100.0 * share);
}

}  // namespace ftstack::diag::fx
