// mains_interference: a sinusoid at a line of the residual spectrum, and its harmonics 2..5 of the
// fitted fundamental, aliased where above Nyquist.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

/// The line's frequency: one cycle in the record to Nyquist (an alias above it shows below).
std::vector<ParamSpec> MainsSpecs(const Context& cx) {
  const auto& t = cx.data->t_s;
  return {{.key = "freq_hz",
           .lo = 1.0 / std::max(t.back() - t.front(), 1e-9),
           .hi = cx.rate_hz / 2.0,
           .lo_what = "one cycle in the record",
           .hi_what = "Nyquist",
           .unit = "Hz",
           .scale = ParamScale::kLinear}};  // searched in Hz: a line's width is 1/duration
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
  const ParamSpec spec = MainsSpecs(cx)[0];
  const Profile profile = [&](double v) { return fit_at(v, nullptr, nullptr); };
  for (std::size_t p = 0; p < std::min<std::size_t>(cx.peak_hz.size(), 3); ++p) {
    // A grid over the line's Welch bin, then a golden refinement to a fraction of 1/duration.
    SolveOptions coarse;
    coarse.golden_steps = 0;
    coarse.sigma_step = 0.0;
    for (int j = -8; j <= 8; ++j) coarse.start.push_back(cx.peak_hz[p] + bin * j / 8.0);
    const double f = SolveParameter(spec, profile, coarse).value;
    SolveOptions fine;
    fine.golden_steps = 30;
    fine.sigma_step = 0.0;
    for (int j = -4; j <= 4; ++j) fine.start.push_back(f + bin / 8.0 * j / 4.0);
    const SolvedParam s = SolveParameter(spec, profile, fine);
    if (s.objective < best_sse) {
      best_sse = s.objective;
      best_f = s.value;
    }
  }
  EffectFit e;
  e.name = "mains_interference";
  e.n_params = 2 * cx.nc + 1;
  ChannelFit cf;
  e.train_sse_w = fit_at(best_f, &e.pred, &cf);
  e.params["freq_hz"] = best_f;
  e.sigma["freq_hz"] = JsonNum(ProfileSigma(profile, best_f, 0.05 / std::max(duration, 1.0)));
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

/// Frequency seen at sampling rate `rate` of a line at f (folded into [0, rate/2]).
double Alias(double f, double rate) {
  const double r = std::fmod(f, rate);
  return r > 0.5 * rate ? rate - r : r;
}

}  // namespace

std::string AddMainsHarmonics(const Context& cx, const Series& target, double f0, EffectFit* e) {
  const auto& d = *cx.data;
  const double nyq = 0.5 * cx.rate_hz;
  const double duration = d.t_s.back() - d.t_s.front();
  const double resolution = 2.0 / std::max(duration, 1.0);  // lines closer than this coincide
  auto fit = [&](const std::vector<double>& fs, Series* pred, int stride) {
    return FitChannels(
        cx, target, 2 * static_cast<int>(fs.size()),
        [&](int i, int, double* x) {
          const double t = d.t_s[static_cast<std::size_t>(i)];
          for (std::size_t k = 0; k < fs.size(); ++k) {
            const double ph = 2.0 * M_PI * fs[k] * t;
            x[2 * k] = std::cos(ph);
            x[2 * k + 1] = std::sin(ph);
          }
        },
        pred, nullptr, stride);
  };
  const int row_step = cx.search_stride;
  std::vector<double> kept{f0};
  std::vector<int> order{1};
  std::string note;
  double sse = fit(kept, nullptr, row_step).sse_w * row_step;
  for (int h = 2; h <= 5; ++h) {
    const double fa = Alias(h * f0, cx.rate_hz);
    bool clash = fa < resolution || fa > nyq - resolution;
    for (double f : kept) clash = clash || std::fabs(f - fa) < resolution;
    if (clash) {
      note += Fmt("; harmonic %d (%.2f Hz) not fitted: aliased onto %s", h, h * f0,
                  fa < resolution || fa > nyq - resolution ? "DC or Nyquist" : "another line");
      continue;
    }
    std::vector<double> trial = kept;
    trial.push_back(fa);
    const double s = fit(trial, nullptr, row_step).sse_w * row_step;
    // The same penalty as every variant choice: ln(n_train·N) per parameter (2 per channel).
    if (sse - s <= 2.0 * cx.nc * Penalty(cx)) continue;
    sse = s;
    kept.push_back(fa);
    order.push_back(h);
    if (h * f0 > nyq)
      note +=
          Fmt("; harmonic %d (%.2f Hz) above Nyquist, fitted at its alias %.2f Hz", h, h * f0, fa);
  }
  if (kept.size() == 1) return note;
  ChannelFit cf = fit(kept, &e->pred, 1);
  e->train_sse_w = cf.sse_w;
  e->n_params += 2 * cx.nc * static_cast<int>(kept.size() - 1);
  e->variant = "mains fundamental with harmonics";
  for (std::size_t k = 0; k < kept.size(); ++k) {
    Vec amp(cx.nc);
    Vec sg(cx.nc);
    const int j = 2 * static_cast<int>(k);
    const Vec cs_a = CoefSigmas(cx, cf, j);
    const Vec cs_b = CoefSigmas(cx, cf, j + 1);
    for (int c = 0; c < cx.nc; ++c) {
      const double a = cf.beta(j, c);
      const double b = cf.beta(j + 1, c);
      amp(c) = std::hypot(a, b);
      const double sa = cs_a(c);
      const double sb = cs_b(c);
      sg(c) = amp(c) > 0 ? std::sqrt(a * a * sa * sa + b * b * sb * sb) / amp(c) : sa;
    }
    const std::string key =
        k == 0 ? std::string("amplitude_mvv") : "h" + std::to_string(order[k]) + "_amplitude_mvv";
    e->params[key] = VecJson(amp);
    e->sigma[key] = VecJson(sg);
    if (k > 0) e->params["h" + std::to_string(order[k]) + "_seen_at_hz"] = kept[k];
  }
  std::string list;
  for (std::size_t k = 1; k < order.size(); ++k)
    list += (k > 1 ? ", " : "") + std::to_string(order[k]);
  return "; harmonics " + list + " kept (each by the BIC penalty)" + note;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec MainsInterferencePlugin() {
  return {.kind = EffectKind::kMainsInterference, .fit = &fx::FitMains, .ranges = &fx::MainsSpecs};
}

}  // namespace ftstack::diag
