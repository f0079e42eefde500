// saturation: a bridge's output clipped at a level.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The extremes of the real (sim + residual) and the simulated outputs over every channel.
struct Extremes {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  double sim_lo = std::numeric_limits<double>::infinity();
  double sim_hi = -std::numeric_limits<double>::infinity();
};

Extremes FindExtremes(const Context& cx, const Series& target) {
  Extremes x;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      const double s = cx.sim_mvv(i, c);
      const double r = s + target(i, c);
      x.hi = std::max(x.hi, r);
      x.lo = std::min(x.lo, r);
      x.sim_hi = std::max(x.sim_hi, s);
      x.sim_lo = std::min(x.sim_lo, s);
    }
  }
  return x;
}

/// The evidence: how many samples where the sim goes beyond the limit read back pinned at it.
std::string PinnedEvidence(const Context& cx, double limit, const Extremes& x) {
  int pinned = 0;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (std::fabs(cx.sim_mvv(i, c)) > limit) ++pinned;
    }
  }
  return Fmt(
      "%d samples where the sim exceeds %.4g mV/V read back pinned at the limit (sim reaches %.4g)",
      pinned, limit, std::max(std::fabs(x.sim_lo), std::fabs(x.sim_hi)));
}

}  // namespace

std::optional<EffectFit> FitSaturation(const Context& cx, const Series& target) {
  // Real = sim + residual; a clipping limit shows up as the extremes of the real outputs.
  const Extremes x = FindExtremes(cx, target);
  const double hi = x.hi;
  const double lo = x.lo;
  const double sim_hi = x.sim_hi;
  const double sim_lo = x.sim_lo;
  // Clipping needs the sim to go beyond what the real file ever reads.
  if (sim_hi <= hi && sim_lo >= lo) return std::nullopt;
  auto predict = [&](double l, double h, Series* out) {
    double sse = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      double acc = 0.0;
      ForRowsWithTraining(cx, 0, cx.n, [&](int i, bool train) {
        const double s = cx.sim_mvv(i, c);
        const double v = std::clamp(s, l, h) - s;
        if (out != nullptr) (*out)(i, c) = v;
        if (train) acc += (target(i, c) - v) * (target(i, c) - v);
      });
      sse += acc * cx.weight(c);
    }
    return sse;
  };
  const double range = std::max(sim_hi - sim_lo, 1e-9);
  // Each limit searched within 4 % of the load's range around the real file's extreme.
  auto refine = [&](double start, bool upper, double other) {
    const ParamSpec spec{.key = upper ? "limit_high" : "limit_low",
                         .lo = start - 0.04 * range,
                         .hi = start + 0.04 * range,
                         .unit = "mV/V",
                         .scale = ParamScale::kLinear,
                         .grid_points = 9,
                         .golden_steps = 12};
    SolveOptions opt;
    opt.sigma_step = 0.0;
    for (int j = -4; j <= 4; ++j) opt.start.push_back(start + 0.01 * range * j);
    return SolveParameter(
               spec,
               [&](double v) {
                 return upper ? predict(other, v, nullptr) : predict(v, other, nullptr);
               },
               opt)
        .value;
  };
  const double h1 = refine(hi, true, -std::numeric_limits<double>::infinity());
  const double l1 = refine(lo, false, h1);
  const double lim = std::max(std::fabs(lo), std::fabs(hi));
  EffectFit e;
  e.name = "saturation";
  e.pred.resize(cx.n, cx.nc);
  const double sse_sym = predict(-lim, lim, nullptr);
  const double sse_asym = predict(l1, h1, nullptr);
  if (sse_sym + Penalty(cx) <= sse_asym + 2 * Penalty(cx)) {
    e.variant = "symmetric limit";
    e.n_params = 1;
    e.train_sse_w = predict(-lim, lim, &e.pred);
    e.params["limit"] = lim;
  } else {
    e.variant = "asymmetric limits";
    e.n_params = 2;
    e.train_sse_w = predict(l1, h1, &e.pred);
    e.params["limit"] = std::max(std::fabs(l1), std::fabs(h1));
    e.params["limit_low"] = l1;
    e.params["limit_high"] = h1;
  }
  e.sigma["limit"] = cx.sigma.maxCoeff() / 2.0;
  e.channels = ActiveChannels(cx, e.pred);
  e.evidence = PinnedEvidence(cx, e.params["limit"].get<double>(), x);
  return e;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

namespace {

/// The clipping level: above zero, below the sim's largest reading (a limit above it clips
/// nothing).
std::vector<ParamSpec> SaturationSpecs(const Context& cx) {
  double peak = 1e-9;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) peak = std::max(peak, std::fabs(cx.sim_mvv(i, c)));
  }
  const auto level = [peak](const char* key, double lo, const char* lo_what) {
    return ParamSpec{.key = key,
                     .lo = lo,
                     .hi = peak,
                     .lo_what = lo_what,
                     .hi_what = "the sim's largest reading",
                     .unit = "mV/V",
                     .scale = ParamScale::kLinear};
  };
  // Each side's level is searched near the real file's extreme, inside these.
  return {level("limit", 0.0, "zero"),
          level("limit_high", -peak, "minus the sim's largest reading"),
          level("limit_low", -peak, "minus the sim's largest reading")};
}

}  // namespace

EffectSpec SaturationPlugin() {
  return {.kind = EffectKind::kSaturation, .fit = &fx::FitSaturation, .ranges = &SaturationSpecs};
}

}  // namespace ftstack::diag
