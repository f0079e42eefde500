// bridge_nonlinearity: a quadratic term of a bridge's own output.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/effects/selected_channels.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitBridgeNonlinearity(const Context& cx, const Series& target) {
  std::vector<int> sel;
  ChannelFit f;
  auto e = SelectedChannelFit(
      cx, target,
      [&](int i, int c, double* x) {
        const double l = cx.load(i, c);
        x[0] = l * l;
      },
      "bridge_nonlinearity", "quadratic_per_mvv", &sel, &f);
  const int c = sel.front();
  e->evidence = Fmt(
      "residual of %s grows with the square of its output (same sign for + and − load), r = %.2f, "
      "%.3g mV/V at full scale",
      ChannelList(sel).c_str(), RowCorr(cx, target, e->pred, c),
      f.beta(0, c) * cx.load.col(c).cwiseAbs().maxCoeff() * cx.load.col(c).cwiseAbs().maxCoeff());
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec BridgeNonlinearityPlugin() {
  return {.kind = EffectKind::kBridgeNonlinearity, .fit = &fx::FitBridgeNonlinearity};
}

}  // namespace ftstack::diag
