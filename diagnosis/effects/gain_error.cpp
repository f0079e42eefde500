// gain_error: a bridge's sensitivity off by a factor (one coefficient on its load).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/effects/selected_channels.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitGainError(const Context& cx, const Series& target) {
  std::vector<int> sel;
  ChannelFit f;
  auto e = SelectedChannelFit(
      cx, target, [&](int i, int c, double* x) { x[0] = cx.load(i, c); }, "gain_error", "gain",
      &sel, &f);
  auto gains = nlohmann::json::array();
  for (int c : sel) gains.push_back(1.0 + f.beta(0, c));
  e->params["gain"] = gains;
  const int c = sel.front();
  e->evidence =
      Fmt("residual of %s is proportional to its own load output (r = %.2f): gain real/sim = %.5f, "
          "other channels unaffected",
          ChannelList(sel).c_str(), RowCorr(cx, target, e->pred, c), 1.0 + f.beta(0, c));
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec GainErrorPlugin() { return {.kind = EffectKind::kGainError, .fit = &fx::FitGainError}; }

}  // namespace ftstack::diag
