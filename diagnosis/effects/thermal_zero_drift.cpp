// thermal_zero_drift: an offset per kelvin of temperature change per bridge, and its variant with a
// fitted lag between thermometer and gauges (the gauges see the thermometer's temperature through a
// first-order lag τ ≥ 0: heat flowing through the body).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag::fx {

std::optional<EffectFit> FitThermalZeroPlain(const Context& cx, const Series& target) {
  return FitThermalZeroOn(cx, target, cx.dtemp);
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

std::optional<EffectFit> FitThermalZeroOn(const Context& cx, const Series& target,
                                          const std::vector<double>& dtemp) {
  if (dtemp.empty()) return std::nullopt;
  EffectFit e;
  e.name = "thermal_zero_drift";
  const auto f = FitChannels(
      cx, target, 2,
      [&](int i, int, double* x) {
        x[0] = 1.0;
        x[1] = dtemp[static_cast<std::size_t>(i)];
      },
      &e.pred);
  e.n_params = 2 * cx.nc;
  const Vec k = PutChannelCoef(cx, f, 1, "coef_per_K", &e);
  e.train_sse_w = f.sse_w;
  e.channels = ActiveChannels(cx, e.pred);
  const int c = DominantChannel(cx, e.pred);
  // Compare with a straight line in time (same parameter count).
  Series lin;
  FitChannels(
      cx, target, 2,
      [&](int i, int, double* x) {
        x[0] = 1.0;
        x[1] = cx.data->t_s[static_cast<std::size_t>(i)];
      },
      &lin);
  e.evidence = Fmt(
      "residual of b%d follows temperature, r = %.2f (a line in time: r = %.2f), %+.3g mV/V per K",
      c, RowCorr(cx, target, e.pred, c), RowCorr(cx, target, lin, c), k(c));
  return e;
}

}  // namespace ftstack::diag

namespace ftstack::diag {

std::vector<ParamSpec> ThermalLagSpecs(const Context& cx) {
  const auto& t = cx.data->t_s;
  return {{.key = "lag_s",
           .lo = std::max(2.0 * cx.dt, 1e-3),
           .hi = std::max((t.back() - t.front()) / 6.0, 4.0 * cx.dt),
           .lo_what = "2 samples",
           .hi_what = "a sixth of the record",
           .unit = "s",
           .grid_points = 14,
           .golden_steps = 12}};
}

std::optional<EffectFit> FitThermalZeroLagged(const Context& cx, const Series& target) {
  if (cx.dtemp.empty()) return std::nullopt;
  const auto& t = cx.data->t_s;
  const std::uint8_t* restart = cx.restart.empty() ? nullptr : cx.restart.data();
  std::vector<double> lagged(cx.dtemp.size());
  auto at = [&](double tau) {
    if (tau <= 0) return FitThermalZeroOn(cx, target, cx.dtemp);
    const double* in[1] = {cx.dtemp.data()};
    double* out[1] = {lagged.data()};
    FirstOrderLowPassColumns(t.data(), t.size(), tau, in, out, 1, restart);
    return FitThermalZeroOn(cx, target, lagged);
  };
  auto sse = [&](double log_tau) {
    const auto f = at(std::exp(log_tau));
    return f ? f->train_sse_w : std::numeric_limits<double>::infinity();
  };
  const auto none = at(0.0);
  if (!none) return std::nullopt;
  const SolvedParam s = SolveParameter(ThermalLagSpecs(cx)[0], sse, {.sigma_step = 0.05});
  const double best_sse = s.objective;
  // The lag must pay for itself clearly (as a whole extra effect would): else the plain model.
  const double margin = 10.0 * std::log(std::max<double>(2.0, static_cast<double>(cx.n_train)));
  if (!(best_sse < none->train_sse_w - margin)) return none;
  const double tau = s.value;
  auto fit = at(tau);
  if (!fit) return none;
  fit->params["lag_s"] = tau;
  fit->sigma["lag_s"] = fx::JsonNum(s.sigma);
  fit->variant = "offset + k·LP_τ[ΔT] (the gauges' temperature lags the thermometer by τ)";
  fit->n_params += 1;
  char buf[96];
  std::snprintf(buf, sizeof buf, "; the gauges follow the thermometer with a lag τ = %.3g s", tau);
  fit->evidence += buf;
  return fit;
}

std::optional<EffectFit> RefineWithThermalLag(const Context& cx, const Series& target) {
  auto lagged = FitThermalZeroLagged(cx, target);
  if (!lagged || !lagged->params.contains("lag_s")) return std::nullopt;
  return lagged;
}

}  // namespace ftstack::diag

namespace ftstack::diag {

EffectSpec ThermalZeroDriftPlugin() {
  return {.kind = EffectKind::kThermalZeroDrift,
          .traits = kTimeBased | kNeedsTemperature,
          .confounders = kConfoundersOfTime | kTimeDrift,
          .fit = &fx::FitThermalZeroPlain,
          .refine_claim = &RefineWithThermalLag,
          .ranges = &ThermalLagSpecs};
}

}  // namespace ftstack::diag
