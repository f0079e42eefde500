// overload_shift: a permanent zero step after an overload.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitOverloadShift(const Context& cx, const Series& target) {
  const auto& d = *cx.data;
  std::vector<int> rows;
  for (int i = 0; i < cx.n; ++i) {
    if (cx.train[static_cast<std::size_t>(i)]) rows.push_back(i);
  }
  const auto m = rows.size();
  if (m < 40) return std::nullopt;
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
  const double t_after = d.t_s[static_cast<std::size_t>(rows[bj])];
  const double t_before = d.t_s[static_cast<std::size_t>(rows[bj - 1])];
  const double onset = rows[bj] - rows[bj - 1] > 1 ? 0.5 * (t_before + t_after) : t_after;
  EffectFit e;
  e.name = "overload_shift";
  e.n_params = cx.nc + 1;
  const auto f = FitChannels(
      cx, target, 1,
      [&](int i, int, double* x) {
        x[0] = d.t_s[static_cast<std::size_t>(i)] >= onset ? 1.0 : 0.0;
      },
      &e.pred);
  e.train_sse_w = f.sse_w;
  const Vec a = PutChannelCoef(cx, f, 0, "shift", &e);
  e.params["onset_s"] = onset;
  e.sigma["onset_s"] = std::max(cx.dt, (t_after - t_before) / std::sqrt(12.0));
  e.channels = ActiveChannels(cx, e.pred);
  // The load peak nearest before the onset (an overload is the physical cause).
  std::string load_note;
  if (d.has_wrench()) {
    double peak = 0.0;
    int pk = 0;
    int pi = 0;
    double scale[6];
    for (int k = 0; k < 6; ++k)
      scale[k] = std::max<double>(d.wrench.col(k).cwiseAbs().maxCoeff(), 1e-12);
    for (int i = 0; i < cx.n && d.t_s[static_cast<std::size_t>(i)] <= onset + 2.0 * cx.block_s;
         ++i) {
      for (int k = 0; k < 6; ++k) {
        const double v = std::fabs(d.wrench(i, k)) / scale[k];
        if (v > peak) {
          peak = v;
          pk = k;
          pi = i;
        }
      }
    }
    load_note = Fmt(", after the largest load so far (%s = %.4g at t = %.2f s)",
                    kWrenchAxisNames[pk], d.wrench(pi, pk), d.t_s[static_cast<std::size_t>(pi)]);
  }
  const int c = DominantChannel(cx, e.pred);
  e.evidence = Fmt("zero of b%d steps by %+.3g mV/V (%.1f σ) at t = %.2f s and stays%s", c, a(c),
                   std::fabs(a(c)) / cx.sigma(c), onset, load_note.c_str());
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec OverloadShiftPlugin() {
  return {.kind = EffectKind::kOverloadShift, .traits = kTimeBased, .fit = &fx::FitOverloadShift};
}

}  // namespace ftstack::diag
