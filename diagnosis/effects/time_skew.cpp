// time_skew: the recording delayed against the simulation.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The delay: a tenth of the record either way (a longer one is a misaligned file, not a skew);
/// searched around the closed-form estimate from the sim's slope.
std::vector<ParamSpec> TimeSkewSpecs(const Context& cx) {
  const auto& t = cx.data->t_s;
  const double d = std::max((t.back() - t.front()) / 10.0, 10.0 * cx.dt);
  return {{.key = "delay_s",
           .lo = -d,
           .hi = d,
           .lo_what = "a tenth of the record (real leads)",
           .hi_what = "a tenth of the record (real lags)",
           .unit = "s",
           .scale = ParamScale::kLinear}};
}

}  // namespace

std::optional<EffectFit> FitTimeSkew(const Context& cx, const Series& target) {
  const auto& d = *cx.data;
  auto predict = [&](double delay, Series* out) {
    double sse = 0.0;
    const int row_step = out == nullptr ? cx.search_stride : 1;
    for (int c = 0; c < cx.nc; ++c) {
      const double* s = cx.load.col(c).data();  // load = sim − zero: the same differences
      double acc = 0.0;
      ForRowsWithTraining(
          cx, 0, cx.n,
          [&](int i, bool tr) {
            if (!tr && out == nullptr) return;
            const double v = InterpolateNear(d.t_s.data(), s, static_cast<std::size_t>(cx.n),
                                             d.t_s[static_cast<std::size_t>(i)] - delay, cx.uniform,
                                             static_cast<std::size_t>(i)) -
                             s[i];
            if (out != nullptr) (*out)(i, c) = static_cast<float>(v);
            if (tr) acc += (target(i, c) - v) * (target(i, c) - v);
          },
          row_step);
      sse += acc * cx.weight(c) * row_step;
    }
    return sse;
  };
  // Linear estimate r ≈ −delay·ds/dt.
  double num = 0.0;
  double den = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    ForTrainingRows(cx, 1, cx.n - 1, [&](int i) {
      const double ds =
          (cx.sim_mvv(i + 1, c) - cx.sim_mvv(i - 1, c)) /
          (d.t_s[static_cast<std::size_t>(i + 1)] - d.t_s[static_cast<std::size_t>(i - 1)]);
      num += -target(i, c) * ds * cx.weight(c);
      den += ds * ds * cx.weight(c);
    });
  }
  if (den <= 0) return std::nullopt;
  const double d0 = num / den;
  const double span = std::max(2.0 * cx.dt, std::fabs(d0));
  SolveOptions opt{.golden_steps = 16, .sigma_step = 0.02 * cx.dt};
  for (int j = -6; j <= 6; ++j) opt.start.push_back(d0 + span * j / 6.0);
  const SolvedParam s = SolveParameter(
      TimeSkewSpecs(cx)[0], [&](double v) { return predict(v, nullptr); }, opt);
  const double delay = s.value;
  EffectFit e;
  e.name = "time_skew";
  e.n_params = 1;
  e.pred.resize(cx.n, cx.nc);
  e.train_sse_w = predict(delay, &e.pred);
  e.params["delay_s"] = delay;
  e.sigma["delay_s"] = JsonNum(s.sigma);
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  e.evidence =
      Fmt("residual of b%d is −delay × d(sim)/dt, largest on fast ramps and zero on holds: real %s "
          "by %.3g ms (%.2f samples), r = %.2f",
          c, delay >= 0 ? "lags" : "leads", std::fabs(delay) * 1e3, std::fabs(delay) / cx.dt,
          RowCorr(cx, target, e.pred, c));
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec TimeSkewPlugin() {
  return {.kind = EffectKind::kTimeSkew, .fit = &fx::FitTimeSkew, .ranges = &fx::TimeSkewSpecs};
}

}  // namespace ftstack::diag
