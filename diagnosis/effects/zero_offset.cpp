// zero_offset: a constant offset per bridge.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitZeroOffset(const Context& cx, const Series& target) {
  EffectFit e;
  e.name = "zero_offset";
  const auto f = FitChannels(
      cx, target, 1, [](int, int, double* x) { x[0] = 1.0; }, &e.pred);
  e.n_params = cx.nc;
  const Vec off = PutChannelCoef(cx, f, 0, "offset", &e);
  e.train_sse_w = f.sse_w;
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual is a constant %+.3g mV/V (%.1f noise σ) on b%d, the same in every time block",
          off(c), std::fabs(off(c)) / cx.sigma(c), c);
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ZeroOffsetPlugin() {
  return {.kind = EffectKind::kZeroOffset, .fit = &fx::FitZeroOffset};
}

}  // namespace ftstack::diag
