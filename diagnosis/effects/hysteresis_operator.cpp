// hysteresis as one rate-independent operator (Dahl or play) per bridge, width searched.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

std::optional<EffectFit> FitHysteresisOperator(const Context& cx, const Series& target) {
  // Two rate-independent operators on each bridge's own load history: Dahl (exponential approach
  // after a reversal) and play/backlash (linear approach, then flat); width searched for each.
  Mat z(cx.n, cx.nc);
  auto build = [&](double log_w, bool play) {
    for (int c = 0; c < cx.nc; ++c) {
      const double width = std::exp(log_w) * std::max(cx.load_range(c), 1e-12);
      if (play) {
        PlayOperator(cx.load.col(c).data(), static_cast<std::size_t>(cx.n), width, z.col(c).data());
      } else {
        DahlOperator(cx.load.col(c).data(), static_cast<std::size_t>(cx.n), width, z.col(c).data());
      }
    }
  };
  auto sse_for = [&](double log_w, bool play) {
    build(log_w, play);
    return SearchSse(cx, target, z);
  };
  std::vector<double> grid;
  for (int j = 0; j <= 10; ++j)
    grid.push_back(std::log(0.002) + (std::log(2.0) - std::log(0.002)) * j / 10.0);
  EffectFit best;
  for (bool play : {false, true}) {
    auto f1 = [&](double v) { return sse_for(v, play); };
    const double lw = MinimizeOnGrid(f1, grid, 10, nullptr);
    EffectFit e;
    e.name = "hysteresis";
    e.variant = play ? "rate-independent play (backlash) operator on each bridge's load"
                     : "rate-independent Dahl operator on each bridge's load";
    e.n_params = cx.nc + 1;
    const double sl = CurvatureSigma(f1, lw, 0.02);
    build(lw, play);
    const auto f = FitChannels(
        cx, target, 1, [&](int i, int c, double* x) { x[0] = z(i, c); }, &e.pred);
    e.train_sse_w = f.sse_w;
    if (!best.name.empty() && best.train_sse_w <= e.train_sse_w) continue;
    PutChannelCoef(cx, f, 0, "half_width_mvv", &e);
    e.params["travel_fraction"] = std::exp(lw);
    e.sigma["travel_fraction"] = JsonNum(std::exp(lw) * sl);
    best = std::move(e);
  }
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  const double h = best.params["half_width_mvv"][static_cast<std::size_t>(c)].get<double>();
  best.evidence = Fmt(
      "at the same load b%d reads %.3g mV/V differently when the load came from above than from "
      "below (%.1f σ), constant during holds, r = %.2f",
      c, 2.0 * std::fabs(h), 2.0 * std::fabs(h) / cx.sigma(c), RowCorr(cx, target, best.pred, c));
  return best;
}

}  // namespace ftstack::diag
