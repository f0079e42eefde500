// Data conditioning: glitches, transitions and quiet noise, found before any effect is fitted.
#include "diagnosis/engine/conditioning.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "diagnosis/engine/parallel.hpp"

namespace ftstack::diag {

namespace {

/// The measured bridge of channel c (residual + load + zero), mV/V.
std::vector<double> RealColumn(const Context& cx, int c) {
  std::vector<double> x(static_cast<std::size_t>(cx.n));
  for (int i = 0; i < cx.n; ++i) {
    x[static_cast<std::size_t>(i)] =
        static_cast<double>(cx.resid(i, c)) + cx.load(i, c) + cx.zero(c);
  }
  return x;
}

double Median(std::vector<double>* v) {
  if (v->empty()) return 0.0;
  const auto mid = v->begin() + static_cast<std::ptrdiff_t>(v->size() / 2);
  std::nth_element(v->begin(), mid, v->end());
  return *mid;
}

/// Robust σ of white noise from the first differences of x over rows [a, b): the median absolute
/// difference / (0.6745 √2). Slow signals (drift, creep) barely move it.
template <class Get>
double DiffSigma(Get x, int a, int b) {
  std::vector<double> d;
  d.reserve(static_cast<std::size_t>(std::max(0, b - a)));
  for (int i = a + 1; i < b; ++i) d.push_back(std::fabs(x(i) - x(i - 1)));
  return Median(&d) / 0.6745 / std::sqrt(2.0);
}

/// Robust σ of white noise from the first differences of x over rows [a, b) taken about their
/// median: a steady ramp (a constant difference) adds nothing, a knock or ringing does.
template <class Get>
double DetrendedDiffSigma(Get x, int a, int b) {
  std::vector<double> d;
  d.reserve(static_cast<std::size_t>(std::max(0, b - a)));
  for (int i = a + 1; i < b; ++i) d.push_back(x(i) - x(i - 1));
  std::vector<double> work = d;
  const double mid = Median(&work);
  for (double& v : d) v = std::fabs(v - mid);
  return Median(&d) / 0.6745 / std::sqrt(2.0);
}

bool NearRestart(const Context& cx, int i, int reach) {
  if (cx.restart.empty()) return false;
  for (int k = std::max(1, i - reach + 1); k <= std::min(cx.n - 1, i + reach); ++k) {
    if (cx.restart[static_cast<std::size_t>(k)] != 0) return true;
  }
  return false;
}

void Exclude(Context* cx, int a, int b) {
  if (cx->excluded.empty()) cx->excluded.assign(static_cast<std::size_t>(cx->n), 0);
  for (int i = std::max(0, a); i <= std::min(cx->n - 1, b); ++i)
    cx->excluded[static_cast<std::size_t>(i)] = 1;
}

/// The line through the four neighbours of row i (rows i-2, i-1, i+1, i+2) of x: its value at i
/// and the spread (max − min) of the neighbours about it. A ramp carries the neighbours apart but
/// keeps them on the line; a knock, an edge or ringing does not.
template <class Get>
void NeighbourLine(Get x, int i, double* at_i, double* spread) {
  const double v[4] = {x(i - 2), x(i - 1), x(i + 1), x(i + 2)};
  const double t[4] = {-2.0, -1.0, 1.0, 2.0};
  const double mean = 0.25 * (v[0] + v[1] + v[2] + v[3]);
  const double slope = (-2.0 * v[0] - v[1] + v[2] + 2.0 * v[3]) / 10.0;
  double lo = 0.0;
  double hi = 0.0;
  for (int k = 0; k < 4; ++k) {
    const double r = v[k] - mean - slope * t[k];
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  *at_i = mean;
  *spread = hi - lo;
}

/// Isolated wrong codes per channel: a sample further than kGlitchSigmas σ from the line through
/// its four neighbours and more than four times their spread about it (so a wrong code on a load
/// ramp is found as on a hold). The residual there becomes the line's value through its
/// neighbours' residuals (so spectra and filters see no spike) and the row is excluded.
void FindGlitches(Context* cx, Conditioning* out) {
  // Channels side by side: each repairs its own column of the residual; the rows to exclude are
  // marked afterwards, in channel order.
  std::vector<std::vector<Glitch>> found(static_cast<std::size_t>(cx->nc));
  ParallelFor(found.size(), cx->threads, [&](std::size_t ch) {
    const int c = static_cast<int>(ch);
    const std::vector<double> x = RealColumn(*cx, c);
    const auto at = [&x](int i) { return x[static_cast<std::size_t>(i)]; };
    double scale = 0.0;
    for (const double v : x) scale = std::max(scale, std::fabs(v));
    const double sigma = std::max(DiffSigma(at, 0, cx->n), 1e-9 * scale + 1e-12);
    for (int i = 2; i + 2 < cx->n; ++i) {
      double line = 0.0;
      double spread = 0.0;
      NeighbourLine(at, i, &line, &spread);
      const double dev = at(i) - line;
      if (std::fabs(dev) <= kGlitchSigmas * sigma || std::fabs(dev) <= 4.0 * spread ||
          NearRestart(*cx, i, 2)) {
        continue;
      }
      // Against the local activity too: a knock or a bouncing weight moves the samples around it.
      const double local = DetrendedDiffSigma(at, std::max(0, i - kGlitchReach),
                                              std::min(cx->n, i + kGlitchReach + 1));
      if (std::fabs(dev) <= kGlitchSigmas * local) continue;
      double repaired = 0.0;
      NeighbourLine([cx, c](int k) { return static_cast<double>(cx->resid(k, c)); }, i, &repaired,
                    &spread);
      cx->resid(i, c) = static_cast<float>(repaired);
      found[ch].push_back({i, c, cx->data->t_s[static_cast<std::size_t>(i)], dev});
    }
  });
  for (const std::vector<Glitch>& g : found) {
    for (const Glitch& one : g) {
      out->glitches.push_back(one);
      Exclude(cx, one.row, one.row);
    }
  }
  std::sort(out->glitches.begin(), out->glitches.end(),
            [](const Glitch& a, const Glitch& b) { return a.row < b.row; });
}

/// Rows where the reference load changes (any channel moves by more than 1e-6 of its range).
std::vector<std::uint8_t> MovingRows(const Context& cx) {
  std::vector<std::uint8_t> moving(static_cast<std::size_t>(cx.n), 0);
  for (int i = 1; i < cx.n; ++i) {
    for (int c = 0; c < cx.nc; ++c) {
      if (cx.load_range(c) > 0 &&
          std::fabs(cx.load(i, c) - cx.load(i - 1, c)) > 1e-6 * cx.load_range(c)) {
        moving[static_cast<std::size_t>(i)] = 1;
        break;
      }
    }
  }
  return moving;
}

/// A reference change: rows [s, e] move, holds before [hb, s) and after (e, ha].
struct Edge {
  int hb = 0;
  int s = 0;
  int e = 0;
  int ha = 0;
};

std::vector<Edge> Edges(const Context& cx, const std::vector<std::uint8_t>& moving) {
  std::vector<Edge> runs;
  for (int i = 0; i < cx.n; ++i) {
    if (moving[static_cast<std::size_t>(i)] == 0) continue;
    if (!runs.empty() && runs.back().e == i - 1) {
      runs.back().e = i;
    } else {
      runs.push_back({0, i, i, 0});
    }
  }
  for (std::size_t k = 0; k < runs.size(); ++k) {
    runs[k].hb = k == 0 ? 0 : runs[k - 1].e + 1;
    runs[k].ha = k + 1 == runs.size() ? cx.n - 1 : runs[k + 1].s - 1;
  }
  return runs;
}

/// First row in [a, b] where f(i) ≥ level, or −1.
template <class F>
int FirstAtLeast(F f, int a, int b, double level) {
  for (int i = a; i <= b; ++i) {
    if (f(i) >= level) return i;
  }
  return -1;
}

/// The channels an edge moves clearly (relative to their range: at least 0.05 and half the
/// largest), the largest first: each settles at its own time (a hand-hung weight loads the cells
/// unevenly).
std::vector<int> EdgeChannels(const Context& cx, const Edge& g) {
  std::vector<std::pair<double, int>> rel;
  double best = 0.0;
  for (int k = 0; k < cx.nc; ++k) {
    if (cx.load_range(k) <= 0) continue;
    const double r = std::fabs(cx.load(g.e, k) - cx.load(g.s - 1, k)) / cx.load_range(k);
    rel.emplace_back(r, k);
    best = std::max(best, r);
  }
  std::stable_sort(rel.begin(), rel.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> out;
  for (const auto& [r, k] : rel) {
    if (r >= 0.05 && r >= 0.5 * best) out.push_back(k);
  }
  return out;
}

/// Widens a lagging channel's window [from, to] to where its load has really changed and settled.
/// Before (when the window starts by the reference's change `s`): back to row `a` while the real
/// load is off its level before the change by more than kTransitionFootSigmas robust σ of that
/// level (a smooth ramp's foot lies inside the band). After: on to `last` while the activity
/// (robust σ of first differences over a second) is over kBounceDecayFactor times the level it
/// settles to 3–5 s later: a hanger's bounce dies within it, while a swinging weight's ringing,
/// creep and noise do not decay that fast and stay in.
template <class U>
void SettleWindow(U u, int a, int s, int last, double rate_hz, int* from, int* to) {
  std::vector<double> pre;
  for (int i = a; i < s; ++i) pre.push_back(u(i));
  if (pre.size() >= 3 && *from <= s) {
    std::vector<double> dev;
    const double level = Median(&pre);
    for (int i = a; i < s; ++i) dev.push_back(std::fabs(u(i) - level));
    const double spread = Median(&dev) / 0.6745;  // robust σ: median absolute deviation
    while (*from > a && std::fabs(u(*from - 1) - level) > kTransitionFootSigmas * spread) --*from;
  }
  const int w = std::max(6, static_cast<int>(std::lround(rate_hz)));
  const int first = std::max(s, *to + 1 - w / 2);
  if (first + 3 * w > last) return;
  // activity(k): the robust σ of first differences over rows first + k … first + k + w − 1, which
  // speaks for its middle rows; each is computed once, and only as far as the bounce lasts.
  std::vector<double> memo(static_cast<std::size_t>(last - first - w + 1), -1.0);
  const auto activity = [&](int k) {
    double& m = memo[static_cast<std::size_t>(k)];
    if (m < 0) m = DetrendedDiffSigma(u, first + k, first + k + w);
    return m;
  };
  // The level it settles to: the median activity 3, 4 and 5 s on (those that fit before `last`),
  // where a bounce has died and a swing, creep and noise have barely changed. Not the next second:
  // the ramp's tail in the first window and a bounce still alive in the next keep their ratio low.
  const auto settled = [&](int k) {
    std::vector<double> later;
    for (int j = 3; j <= kSettleSeconds && first + k + (j + 1) * w <= last; ++j)
      later.push_back(activity(k + j * w));
    if (later.empty()) later.push_back(std::max(activity(k + w), activity(k + 2 * w)));
    return Median(&later);
  };
  for (int k = 0; first + k + 3 * w <= last; ++k) {
    if (activity(k) <= kBounceDecayFactor * settled(k)) break;
    *to = std::max(*to, first + k + w / 2);
  }
}

/// Measures one edge on channel c: the real load normalised by its own levels before and after
/// against the normalised reference. Returns false when the edge cannot be measured there (short
/// holds, a real change unlike the reference's).
bool MeasureEdge(const Context& cx, const Edge& g, int c, const std::vector<double>& sigma,
                 Transition* t, int* from, int* to) {
  const int before = g.s - g.hb;
  const int after = g.ha - g.e;
  if (before < 3 || after < 6) return false;
  const auto real = [&](int i) {
    return static_cast<double>(cx.resid(i, c)) + cx.load(i, c) + cx.zero(c);
  };
  const int p = std::min(before, std::max(3, static_cast<int>(std::lround(2.0 * cx.rate_hz))));
  std::vector<double> pre_v;
  std::vector<double> post_v;
  for (int i = g.s - p; i < g.s; ++i) pre_v.push_back(real(i));
  for (int i = g.e + 1 + after / 2; i <= g.ha; ++i) post_v.push_back(real(i));
  const double pre = Median(&pre_v);
  const double d_real = Median(&post_v) - pre;
  const double d_ref = cx.load(g.e, c) - cx.load(g.s - 1, c);
  if (d_real * d_ref <= 0 || std::fabs(d_real) < 0.5 * std::fabs(d_ref)) return false;
  const auto u = [&](int i) { return (real(i) - pre) / d_real; };
  const auto v = [&](int i) { return (cx.load(i, c) - cx.load(g.s - 1, c)) / d_ref; };
  const int a = g.s - p;
  const int b = g.e + after / 2;
  const double band =
      std::max(kTransitionBand, 6.0 * sigma[static_cast<std::size_t>(c)] / std::fabs(d_real));
  *from = -1;
  *to = -1;
  for (int i = a; i <= b; ++i) {
    if (std::fabs(u(i) - v(i)) <= band) continue;
    if (*from < 0) *from = i;
    *to = i;
  }
  const int u10 = FirstAtLeast(u, a, b, 0.1);
  const int u90 = u10 < 0 ? -1 : FirstAtLeast(u, u10, b, 0.9);
  const int v10 = FirstAtLeast(v, a, b, 0.1);
  const int v90 = v10 < 0 ? -1 : FirstAtLeast(v, v10, b, 0.9);
  if (u90 < 0 || v90 < 0) return false;
  t->first_row = g.s;
  t->channel = c;
  t->t_s = cx.data->t_s[static_cast<std::size_t>(g.s)];
  t->step_mvv = d_ref;
  t->application_s = static_cast<double>(u90 - u10) * cx.dt / 0.8;
  // Lagging: the real load rises clearly slower than the reference (a skew keeps the shape).
  t->excluded =
      *from >= 0 && (u90 - u10) - (v90 - v10) >= 2 && (u90 - u10) > (v90 - v10) + (v90 - v10) / 2;
  if (t->excluded) SettleWindow(u, a, g.s, g.e + after / 2, cx.rate_hz, from, to);
  return true;
}

/// Reference changes between holds, each measured on every channel it moves clearly; the rows where
/// any of them lags are excluded (the union of their windows, with one row of margin each side).
/// The transition reported is the lagging channel whose own window (rows off the reference) is
/// longest, else the one of largest change.
void FindTransitions(Context* cx, Conditioning* out, const std::vector<std::uint8_t>& moving,
                     const std::vector<double>& sigma) {
  for (const Edge& g : Edges(*cx, moving)) {
    Transition shown;
    int shown_rows = -1;  // the shown channel's own window, in rows (last − first)
    bool measured = false;
    int from = -1;
    int to = -1;
    for (const int c : EdgeChannels(*cx, g)) {
      Transition t;
      int f = -1;
      int e = -1;
      if (!MeasureEdge(*cx, g, c, sigma, &t, &f, &e)) continue;
      if (!measured || (t.excluded && (!shown.excluded || e - f > shown_rows))) {
        shown = t;
        shown_rows = e - f;
      }
      measured = true;
      if (!t.excluded) continue;
      from = from < 0 ? f : std::min(from, f);
      to = std::max(to, e);
    }
    if (!measured) continue;
    if (from >= 0) {
      Exclude(cx, from - 1, to + 1);
      shown.excluded = true;
      shown.excluded_from_s = cx->data->t_s[static_cast<std::size_t>(std::max(0, from - 1))];
      shown.excluded_to_s = cx->data->t_s[static_cast<std::size_t>(std::min(cx->n - 1, to + 1))];
    }
    out->transitions.push_back(shown);
  }
}

/// Each channel's noise in its quietest hold (rows neither moving nor excluded, at least 20 rows
/// and 1 s): the robust σ of first differences there (ringing, bounce or creep lift the others).
void MeasureQuietNoise(const Context& cx, Conditioning* out,
                       const std::vector<std::uint8_t>& moving) {
  const int min_rows = std::max(20, static_cast<int>(std::lround(cx.rate_hz)));
  std::vector<std::pair<int, int>> holds;
  int start = -1;
  for (int i = 0; i <= cx.n; ++i) {
    const bool quiet =
        i < cx.n && moving[static_cast<std::size_t>(i)] == 0 &&
        (cx.excluded.empty() || cx.excluded[static_cast<std::size_t>(i)] == 0) &&
        !(start >= 0 && !cx.restart.empty() && cx.restart[static_cast<std::size_t>(i)] != 0);
    if (quiet && start < 0) start = i;
    if (!quiet && start >= 0) {
      if (i - start >= min_rows) holds.emplace_back(start, i);
      start = -1;
    }
  }
  out->noise.assign(static_cast<std::size_t>(cx.nc), QuietNoise{});
  for (int c = 0; c < cx.nc; ++c) {
    std::vector<std::pair<double, std::size_t>> per_hold;
    for (std::size_t h = 0; h < holds.size(); ++h) {
      const auto at = [&](int i) { return static_cast<double>(cx.resid(i, c)); };
      per_hold.emplace_back(DiffSigma(at, holds[h].first, holds[h].second), h);
    }
    if (per_hold.empty()) continue;
    std::sort(per_hold.begin(), per_hold.end());
    // The quietest hold of at least kQuietHoldRows rows (its σ known to ~8 %), else of any length.
    const auto long_enough = [&](const std::pair<double, std::size_t>& h) {
      return holds[h.second].second - holds[h.second].first >= kQuietHoldRows;
    };
    const auto found = std::find_if(per_hold.begin(), per_hold.end(), long_enough);
    const auto& pick = found != per_hold.end() ? *found : per_hold.front();
    QuietNoise& q = out->noise[static_cast<std::size_t>(c)];
    q.sigma_mvv = pick.first;
    std::vector<double> quiet_class;
    for (const auto& h : per_hold) {
      if ((found == per_hold.end() || long_enough(h)) && h.first <= kQuietClass * pick.first)
        quiet_class.push_back(h.first);
    }
    std::nth_element(quiet_class.begin(), quiet_class.begin() + std::ssize(quiet_class) / 2,
                     quiet_class.end());
    q.typical_sigma_mvv = quiet_class[quiet_class.size() / 2];
    q.from_s = cx.data->t_s[static_cast<std::size_t>(holds[pick.second].first)];
    q.to_s = cx.data->t_s[static_cast<std::size_t>(holds[pick.second].second - 1)];
    q.holds = static_cast<int>(holds.size());
  }
}

}  // namespace

void ConditionData(Context* cx) {
  Conditioning out;
  FindGlitches(cx, &out);
  std::vector<double> sigma(static_cast<std::size_t>(cx->nc));
  ParallelFor(sigma.size(), cx->threads, [&](std::size_t ch) {
    const int c = static_cast<int>(ch);
    const auto at = [&](int i) { return static_cast<double>(cx->resid(i, c)); };
    sigma[ch] = DiffSigma(at, 0, cx->n);
  });
  const std::vector<std::uint8_t> moving = MovingRows(*cx);
  FindTransitions(cx, &out, moving, sigma);
  MeasureQuietNoise(*cx, &out, moving);
  if (!cx->excluded.empty()) {
    cx->n_train = 0;
    cx->n_hold = 0;
    for (std::size_t i = 0; i < cx->excluded.size(); ++i) {
      if (cx->excluded[i] != 0) {
        cx->train[i] = 0;
        ++out.excluded_rows;
      } else if (cx->train[i] != 0) {
        ++cx->n_train;
      } else {
        ++cx->n_hold;
      }
    }
  }
  cx->conditioning = std::move(out);
}

}  // namespace ftstack::diag
