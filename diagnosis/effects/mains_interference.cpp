// mains_interference: a harmonic series of spectral lines from a supply (railway 16.7 Hz, mains
// 50/60 Hz, 400 Hz), named at its fundamental even where a harmonic carries the energy, every line
// fitted at its alias where above Nyquist.
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// A supply whose lines a record picks up: its fundamental's plausible span (generators and weak
/// grids run a few per cent off nominal).
struct Supply {
  double lo_hz;
  double hi_hz;
  const char* name;
};
constexpr std::array<Supply, 3> kSupplies{{{16.2, 17.2, "16.7 Hz railway supply"},
                                           {45.0, 65.0, "50/60 Hz mains"},
                                           {380.0, 420.0, "400 Hz supply"}}};
constexpr int kMaxOrder = 5;  ///< harmonics 1..5 of a fundamental form its series

const Supply* SupplyOf(double f) {
  for (const Supply& s : kSupplies) {
    if (f >= s.lo_hz && f <= s.hi_hz) return &s;
  }
  return nullptr;
}

/// Frequency seen at sampling rate `rate` of a line at f (folded into [0, rate/2]).
double Alias(double f, double rate) {
  const double r = std::fmod(f, rate);
  return r > 0.5 * rate ? rate - r : r;
}

/// The largest row stride ≤ the search's at which the lines `hz` (seen at the record's rate) stay
/// apart and off DC and Nyquist once the rows are thinned: a line aliased onto DC at the thinned
/// rate is fitted by any offset (50 Hz at 200 Hz, every 4th row), so it cannot be searched there.
int LineStride(const Context& cx, const std::vector<double>& hz, double margin_hz) {
  for (int s = cx.search_stride; s > 1; --s) {
    const double rate = cx.rate_hz / s;
    bool apart = true;
    for (std::size_t a = 0; a < hz.size() && apart; ++a) {
      const double fa = Alias(hz[a], rate);
      apart = fa > margin_hz && fa < 0.5 * rate - margin_hz;
      for (std::size_t b = 0; b < a && apart; ++b) {
        apart = std::fabs(fa - Alias(hz[b], rate)) > margin_hz;
      }
    }
    if (apart) return s;
  }
  return 1;
}

/// A harmonic series: fundamental f0, the orders kept (1 first) and where each is seen.
struct LineSeries {
  double f0 = 0.0;
  std::vector<int> order;
  std::vector<double> seen_hz;
  double sse = 0.0;               ///< whitened training SSE less that before the series (≤ 0)
  bool fundamental_seen = false;  ///< the fundamental's own line beats its penalty
  std::string note;               ///< harmonics not fitted, and why
  /// A series when two of its lines are significant (their ratio is the evidence), or its
  /// fundamental is, seen where it is (folded from above Nyquist, one line could be any other
  /// line's alias). A lone line elsewhere is a resonance's or unexplained.
  [[nodiscard]] bool Plausible(double nyquist_hz) const {
    const std::size_t significant = order.size() - 1 + (fundamental_seen ? 1 : 0);
    return !order.empty() && (significant >= 2 || (fundamental_seen && f0 <= nyquist_hz));
  }
};

/// Sine and cosine of every line in `seen_hz` on the training rows of the fit. The phases are
/// computed once per row for every channel (a table of the rows used, up to 32 MB; beyond that
/// per row and channel).
ChannelFit FitLines(const Context& cx, const Series& target, const std::vector<double>& seen_hz,
                    Series* pred, int stride) {
  const auto& t = cx.data->t_s;
  const auto lines = static_cast<std::size_t>(seen_hz.size());
  const auto rows = static_cast<std::size_t>((cx.n + stride - 1) / stride);
  const bool tabled =
      (pred == nullptr || stride == 1) && rows * 2 * lines <= (std::size_t{1} << 22);
  std::vector<double> table;
  const auto phases = [&](int i, double* x) {
    const double ti = t[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < lines; ++k) {
      const double ph = 2.0 * M_PI * seen_hz[k] * ti;
      x[2 * k] = std::cos(ph);
      x[2 * k + 1] = std::sin(ph);
    }
  };
  if (tabled) {
    table.resize(rows * 2 * lines);
    for (int i = 0; i < cx.n; i += stride) {
      phases(i, &table[static_cast<std::size_t>(i / stride) * 2 * lines]);
    }
  }
  return FitChannels(
      cx, target, 2 * static_cast<int>(lines),
      [&](int i, int, double* x) {
        if (!tabled) {
          phases(i, x);
          return;
        }
        const double* row = &table[static_cast<std::size_t>(i / stride) * 2 * lines];
        std::copy(row, row + 2 * lines, x);
      },
      pred, nullptr, stride);
}

/// What one line alone removes from the whitened training SSE, remembered per frequency: lines
/// apart by more than the resolution are near orthogonal over the record, so a series' SSE is
/// the sum of its lines' (candidate series share most of their lines; the kept series is then
/// fitted jointly).
class LineGains {
 public:
  LineGains(const Context& cx, const Series& target) : cx_(cx), target_(target) {}
  double Gain(double f, double resolution) {
    for (const auto& [g, gain] : known_) {
      if (std::fabs(g - f) < 0.05 * resolution) return gain;
    }
    const int step = LineStride(cx_, {f}, 2.0 * resolution);
    double before = 0.0;
    for (int c = 0; c < cx_.nc; ++c) {
      double sum = 0.0;
      ForTrainingRows(
          cx_, 0, cx_.n, [&](int i) { sum += static_cast<double>(target_(i, c)) * target_(i, c); },
          step);
      before += sum * cx_.weight(c);
    }
    const double gain = (before - FitLines(cx_, target_, {f}, nullptr, step).sse_w) * step;
    known_.emplace_back(f, gain);
    return gain;
  }

 private:
  const Context& cx_;
  const Series& target_;
  std::vector<std::pair<double, double>> known_;
};

/// The series of f0: the fundamental, then each harmonic 2..5 kept when its line removes more
/// than the penalty of its 2 coefficients per channel (the one every variant choice uses); sse is
/// what the kept lines leave of the training SSE, less the gains. Empty orders when the
/// fundamental's alias sits on DC or Nyquist.
LineSeries ChooseSeries(const Context& cx, LineGains* gains, double f0) {
  const double nyq = 0.5 * cx.rate_hz;
  const auto& t = cx.data->t_s;
  const double resolution = 2.0 / std::max(t.back() - t.front(), 1.0);  // closer lines coincide
  LineSeries s;
  s.f0 = f0;
  const double fa = Alias(f0, cx.rate_hz);
  if (fa < resolution || fa > nyq - resolution) return s;
  const double penalty = 2.0 * cx.nc * Penalty(cx);  // 2 coefficients per channel and line
  s.order = {1};
  s.seen_hz = {fa};
  const double g1 = gains->Gain(fa, resolution);
  s.fundamental_seen = g1 > penalty;
  s.sse = -g1;
  for (int h = 2; h <= kMaxOrder; ++h) {
    const double ha = Alias(h * f0, cx.rate_hz);
    const bool edge = ha < resolution || ha > nyq - resolution;
    bool clash = edge;
    for (double f : s.seen_hz) clash = clash || std::fabs(f - ha) < resolution;
    if (clash) {
      s.note += Fmt("; harmonic %d (%.2f Hz) not fitted: aliased onto %s", h, h * f0,
                    edge ? "DC or Nyquist" : "another line");
      continue;
    }
    const double gain = gains->Gain(ha, resolution);
    if (gain <= penalty) continue;
    s.sse -= gain;
    s.seen_hz.push_back(ha);
    s.order.push_back(h);
    if (h * f0 > nyq) {
      s.note +=
          Fmt("; harmonic %d (%.2f Hz) above Nyquist, fitted at its alias %.2f Hz", h, h * f0, ha);
    }
  }
  return s;
}

/// Whether a line seen at `rate` can tell the h-th harmonic of supply s from other lines: not when
/// that harmonic's span is a whole sampling rate wide or wider, for then it folds onto every
/// frequency of the band (a slow logger: every line is an alias of some mains frequency, with a
/// new candidate every rate/h).
bool Distinguishable(const Supply& s, int h, double rate) { return h * (s.hi_hz - s.lo_hz) < rate; }

/// Supply fundamentals one of whose harmonics 1..5 is seen at `seen` (directly or folded from
/// above Nyquist), each once; harmonics that are not Distinguishable at this rate are not
/// candidates (none at all on a logger slower than every span).
std::vector<double> Fundamentals(double seen, double rate) {
  double top = 0.0;
  for (const Supply& s : kSupplies) {
    for (int h = 1; h <= kMaxOrder; ++h) {
      if (Distinguishable(s, h, rate)) top = std::max(top, h * s.hi_hz);
    }
  }
  std::vector<double> out;
  for (int m = 0; m * rate - seen <= top; ++m) {
    for (double f : {m * rate + seen, m * rate - seen}) {
      if (f <= 0.0) continue;
      for (int h = 1; h <= kMaxOrder; ++h) {
        const double f0 = f / h;
        const Supply* s = SupplyOf(f0);
        if (s == nullptr || !Distinguishable(*s, h, rate)) continue;
        const bool known = std::any_of(out.begin(), out.end(),
                                       [&](double g) { return std::fabs(g - f0) < 1e-9 * f0; });
        if (!known) out.push_back(f0);
      }
    }
  }
  return out;
}

/// The whitened power of every `stride`-th training row at f_lo + j·step (j < count), summed over
/// channels: weight_c·|Σ_i r_ic·e^(−iωt_i)|². A row's phasor is advanced by one rotation per
/// frequency instead of a sine and cosine each.
std::vector<double> LinePower(const Context& cx, const Series& target, double f_lo, double step,
                              int count, int stride) {
  const auto nc = static_cast<std::size_t>(cx.nc);
  std::vector<std::complex<double>> acc(static_cast<std::size_t>(count) * nc);
  const auto& t = cx.data->t_s;
  ForTrainingRows(
      cx, 0, cx.n,
      [&](int i) {
        const auto k = static_cast<std::size_t>(i);
        std::complex<double> ph = std::polar(1.0, -2.0 * M_PI * f_lo * t[k]);
        const std::complex<double> rot = std::polar(1.0, -2.0 * M_PI * step * t[k]);
        for (std::size_t j = 0; j < static_cast<std::size_t>(count); ++j, ph *= rot) {
          for (std::size_t c = 0; c < nc; ++c) {
            acc[j * nc + c] += static_cast<double>(target(i, static_cast<int>(c))) * ph;
          }
        }
      },
      stride);
  std::vector<double> power(static_cast<std::size_t>(count), 0.0);
  for (std::size_t j = 0; j < power.size(); ++j) {
    for (std::size_t c = 0; c < nc; ++c) {
      power[j] += cx.weight(static_cast<int>(c)) * std::norm(acc[j * nc + c]);
    }
  }
  return power;
}

/// The refined frequency of each of the residual's three strongest lines, as seen (aliased): the
/// power on a grid over the line's Welch bin in steps of 0.8/duration (a coarser grid can miss
/// the main lobe and land on a sidelobe of the hold-out gaps), then a golden refinement of the
/// fitted line, on rows thinned only where the line stays clear of DC and Nyquist (LineStride).
std::vector<double> RefinedLines(const Context& cx, const Series& target) {
  const auto& t = cx.data->t_s;
  const double duration = std::max(t.back() - t.front(), 1e-9);
  const double bin = cx.rate_hz / static_cast<double>(WelchSegment(static_cast<std::size_t>(cx.n)));
  const ParamSpec spec{.key = "freq_hz",
                       .lo = 1.0 / duration,
                       .hi = cx.rate_hz / 2.0,
                       .scale = ParamScale::kLinear};  // searched in Hz: a line's width is 1/T
  int stride = 1;
  const Profile profile = [&](double f) {
    return FitLines(cx, target, {f}, nullptr, stride).sse_w;
  };
  // Steps of 0.8/T put a grid point within 0.4/T of the line, where its power is 0.57 of the
  // peak: above the hold-out gaps' sidelobes (0.17) and the record's (0.05).
  const int half = std::clamp(static_cast<int>(std::ceil(bin * duration / 0.8)), 8, 128);
  const double step = bin / half;
  std::vector<double> out;
  for (std::size_t p = 0; p < std::min<std::size_t>(cx.peak_hz.size(), 3); ++p) {
    const double f_lo = std::max(cx.peak_hz[p] - bin, spec.lo);
    stride = LineStride(cx, {cx.peak_hz[p]}, 2.0 * bin);
    const std::vector<double> power = LinePower(cx, target, f_lo, step, 2 * half + 1, stride);
    const auto j = std::max_element(power.begin(), power.end()) - power.begin();
    const double f = f_lo + step * static_cast<double>(j);
    SolveOptions fine;
    fine.golden_steps = 30;
    fine.sigma_step = 0.0;
    for (int k = -4; k <= 4; ++k) fine.start.push_back(f + step * k / 4.0);
    out.push_back(SolveParameter(spec, profile, fine).value);
  }
  return out;
}

/// Which harmonics carry the series' energy (Σ over channels of amplitude², fundamental odd):
/// the even share with its σ, the strongest order, and what that says of the source.
std::string EnergyWords(const Context& cx, const ChannelFit& cf, const LineSeries& s,
                        EffectFit* e) {
  double even = 0.0;
  double all = 0.0;
  std::vector<double> energy(s.order.size(), 0.0);
  for (std::size_t k = 0; k < s.order.size(); ++k) {
    for (int c = 0; c < cx.nc; ++c) {
      const int j = 2 * static_cast<int>(k);
      energy[k] += cf.beta(j, c) * cf.beta(j, c) + cf.beta(j + 1, c) * cf.beta(j + 1, c);
    }
    all += energy[k];
    if (s.order[k] % 2 == 0) even += energy[k];
  }
  if (all <= 0.0) return "";
  const double frac = even / all;
  double var = 0.0;  // d frac / d β = 2β·(even ? 1 − frac : −frac) / all
  for (std::size_t k = 0; k < s.order.size(); ++k) {
    const bool is_even = s.order[k] % 2 == 0;
    const int j = 2 * static_cast<int>(k);
    const Vec sa = CoefSigmas(cx, cf, j);
    const Vec sb = CoefSigmas(cx, cf, j + 1);
    for (int c = 0; c < cx.nc; ++c) {
      const double g = 2.0 * (is_even ? 1.0 - frac : -frac) / all;
      var += std::pow(g * cf.beta(j, c) * sa(c), 2) + std::pow(g * cf.beta(j + 1, c) * sb(c), 2);
    }
  }
  const auto top =
      static_cast<std::size_t>(std::max_element(energy.begin(), energy.end()) - energy.begin());
  e->params["even_harmonic_energy_fraction"] = frac;
  e->sigma["even_harmonic_energy_fraction"] = JsonNum(std::sqrt(var));
  e->params["dominant_harmonic"] = s.order[top];
  const std::string share =
      Fmt("harmonic %d carries %.0f %% of the energy, the even harmonics %.0f %%", s.order[top],
          100.0 * energy[top] / all, 100.0 * frac);
  if (frac > 0.5) return "; " + share + ": a rectified or switched supply's ripple";
  if (s.order.size() > 1) return "; " + share + ": odd harmonics, as of magnetic pick-up";
  return "";
}

/// The series with its fundamental refined on every training row, all its lines moving with it (a
/// fundamental first seen on a weak line is only as exact as that line).
LineSeries RefineSeries(const Context& cx, const Series& target, LineSeries s) {
  const auto& t = cx.data->t_s;
  const double width = 1.0 / std::max(t.back() - t.front(), 1.0) / s.order.back();
  const ParamSpec spec{.key = "freq_hz",
                       .lo = s.f0 - 4.0 * width,
                       .hi = s.f0 + 4.0 * width,
                       .scale = ParamScale::kLinear};
  const int stride = LineStride(cx, s.seen_hz, 2.0 * width * s.order.back());
  const Profile profile = [&](double f) {
    std::vector<double> seen;
    for (int h : s.order) seen.push_back(Alias(h * f, cx.rate_hz));
    return FitLines(cx, target, seen, nullptr, stride).sse_w;
  };
  SolveOptions fine;
  fine.golden_steps = 16;
  fine.sigma_step = 0.0;
  for (int j = -4; j <= 4; ++j) fine.start.push_back(s.f0 + width * j);
  s.f0 = SolveParameter(spec, profile, fine).value;
  for (std::size_t k = 0; k < s.order.size(); ++k)
    s.seen_hz[k] = Alias(s.order[k] * s.f0, cx.rate_hz);
  return s;
}

/// The claimed series: every line's amplitude per channel (σ), where each is seen, the
/// fundamental's frequency with σ from the curvature of the whole series' SSE as it moves (every
/// harmonic with it), which harmonics carry the energy, and the evidence.
EffectFit MainsFit(const Context& cx, const Series& target, const LineSeries& s) {
  EffectFit e;
  e.name = "mains_interference";
  const auto lines = static_cast<int>(s.order.size());
  e.n_params = 2 * cx.nc * lines + 1;
  const ChannelFit cf = FitLines(cx, target, s.seen_hz, &e.pred, 1);
  e.train_sse_w = cf.sse_w;
  const auto& t = cx.data->t_s;
  const Profile profile = [&](double f) {
    std::vector<double> seen;
    for (int h : s.order) seen.push_back(Alias(h * f, cx.rate_hz));
    return FitLines(cx, target, seen, nullptr, 1).sse_w;
  };
  const double step = 0.05 / std::max(t.back() - t.front(), 1.0) / s.order.back();
  const double sf = ProfileSigma(profile, s.f0, step);
  e.params["freq_hz"] = s.f0;
  e.sigma["freq_hz"] = JsonNum(sf);
  std::string list;
  for (int k = 0; k < lines; ++k) {
    Vec amp(cx.nc);
    Vec sg(cx.nc);
    const Vec sa = CoefSigmas(cx, cf, 2 * k);
    const Vec sb = CoefSigmas(cx, cf, 2 * k + 1);
    for (int c = 0; c < cx.nc; ++c) {
      const double a = cf.beta(2 * k, c);
      const double b = cf.beta(2 * k + 1, c);
      amp(c) = std::hypot(a, b);
      sg(c) = amp(c) > 0 ? std::hypot(a * sa(c), b * sb(c)) / amp(c) : sa(c);
    }
    const int h = s.order[static_cast<std::size_t>(k)];
    const std::string prefix = k == 0 ? "" : "h" + std::to_string(h) + "_";
    e.params[prefix + "amplitude_mvv"] = VecJson(amp);
    e.sigma[prefix + "amplitude_mvv"] = VecJson(sg);
    if (k > 0 || s.f0 > 0.5 * cx.rate_hz) {
      e.params[prefix + "seen_at_hz"] = s.seen_hz[static_cast<std::size_t>(k)];
      e.sigma[prefix + "seen_at_hz"] = JsonNum(h * sf);
    }
    if (k > 0) list += (k > 1 ? ", " : "") + std::to_string(h);
  }
  e.variant = lines == 1 ? "mains fundamental" : "mains fundamental with harmonics";
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  const double a1 = e.params["amplitude_mvv"][static_cast<std::size_t>(c)].get<double>();
  e.evidence =
      Fmt("steady lines of a %s, fundamental %.3f Hz, on %s at every load and time; "
          "the fundamental %.3g mV/V (%.1f σ) on b%d",
          SupplyOf(s.f0)->name, s.f0, ChannelList(e.channels).c_str(), a1, a1 / cx.sigma(c), c);
  if (s.f0 > 0.5 * cx.rate_hz) {
    e.evidence +=
        Fmt("; the fundamental is above Nyquist, seen at its alias %.2f Hz", s.seen_hz[0]);
  }
  if (lines > 1) e.evidence += "; harmonics " + list + " kept (each by the BIC penalty)";
  e.evidence += EnergyWords(cx, cf, s, &e) + s.note;
  return e;
}

}  // namespace

/// The series' fundamental: a supply's frequency, which may lie above Nyquist (seen aliased).
std::vector<ParamSpec> MainsSpecs(const Context&) {
  return {{.key = "freq_hz",
           .lo = 10.0,
           .hi = 1000.0,
           .lo_what = "below every supply (16.7 Hz railway)",
           .hi_what = "above every supply (400 Hz)",
           .unit = "Hz",
           .scale = ParamScale::kLog}};
}

std::optional<EffectFit> FitMains(const Context& cx, const Series& target) {
  if (cx.peak_hz.empty()) return std::nullopt;
  const double line_cost = 2.0 * cx.nc * Penalty(cx);
  std::vector<LineSeries> plausible;
  std::vector<double> tried;
  LineGains gains(cx, target);
  for (double seen : RefinedLines(cx, target)) {
    for (double f0 : Fundamentals(seen, cx.rate_hz)) {
      if (std::any_of(tried.begin(), tried.end(),
                      [&](double g) { return std::fabs(g - f0) < 1e-6 * f0; }))
        continue;
      tried.push_back(f0);
      LineSeries s = ChooseSeries(cx, &gains, f0);
      if (s.Plausible(0.5 * cx.rate_hz)) plausible.push_back(std::move(s));
    }
  }
  if (plausible.empty()) return std::nullopt;  // no line belongs to a supply's series
  const auto cost = [&](const LineSeries& s) {
    return s.sse + line_cost * static_cast<double>(s.order.size());
  };
  // The gains add lines as if orthogonal; a line off by a sidelobe of the hold-out gaps shares a
  // true line's power, so the three best by the gains are scored again by their joint fit.
  std::sort(plausible.begin(), plausible.end(),
            [&](const LineSeries& a, const LineSeries& b) { return cost(a) < cost(b); });
  const double resolution = 2.0 / std::max(cx.data->t_s.back() - cx.data->t_s.front(), 1.0);
  const LineSeries* best = &plausible.front();
  double best_joint = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < std::min<std::size_t>(plausible.size(), 3); ++k) {
    const LineSeries& s = plausible[k];
    const int stride = LineStride(cx, s.seen_hz, 2.0 * resolution);
    const double joint = FitLines(cx, target, s.seen_hz, nullptr, stride).sse_w * stride +
                         line_cost * static_cast<double>(s.order.size());
    if (joint < best_joint) {
      best_joint = joint;
      best = &s;
    }
  }
  // Supplies f0 + k·rate put every harmonic on the same aliases: the data cannot tell them apart.
  // The lowest is named, the others said.
  const auto same_lines = [&](const LineSeries& s) {
    if (s.seen_hz.size() != best->seen_hz.size()) return false;
    for (double f : s.seen_hz) {
      if (std::none_of(best->seen_hz.begin(), best->seen_hz.end(),
                       [&](double g) { return std::fabs(f - g) < resolution; }))
        return false;
    }
    return true;
  };
  std::vector<double> alike;
  const LineSeries* named = best;
  for (const LineSeries& s : plausible) {
    if (!same_lines(s)) continue;
    alike.push_back(s.f0);
    if (s.f0 < named->f0) named = &s;
  }
  EffectFit e = MainsFit(cx, target, RefineSeries(cx, target, *named));
  std::sort(alike.begin(), alike.end());
  alike.erase(std::unique(alike.begin(), alike.end(),
                          [&](double a, double b) { return b - a < resolution; }),
              alike.end());
  if (alike.size() > 1) {
    std::string list;
    for (double f : alike) list += Fmt("%s%.2f Hz", list.empty() ? "" : ", ", f);
    e.evidence += "; at this rate supplies of " + list +
                  " put their lines on the same frequencies: the lowest is named";
  }
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec MainsInterferencePlugin() {
  return {.kind = EffectKind::kMainsInterference, .fit = &fx::FitMains, .ranges = &fx::MainsSpecs};
}

}  // namespace ftstack::diag
