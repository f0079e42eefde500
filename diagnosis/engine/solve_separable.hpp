// The engine's whole solve of a separable effect with one declared nonlinear parameter: the
// effect gives its features for a parameter value, the engine searches the parameter, solves the
// linear coefficients, their σ, the prediction and the parameter's status.
#pragma once

#include "diagnosis/engine/separable_fit.hpp"
#include "diagnosis/engine/solve.hpp"

namespace ftstack::diag {

/// What SolveSeparable returns: the parameter as solved, the per-channel linear fit at it (with
/// its σ: fx::CoefSigmas) and that fit's prediction (n × N, mV/V).
struct SeparableSolution {
  SolvedParam param;
  fx::ChannelFit linear;
  Series pred;
};

/// Solves target_c ≈ Σ_j β_jc · x_j(θ, i, c) on the training rows for the parameter θ declared
/// by `spec`: the profile (whitened training SSE of the linear fit) on spec's start grid, golden
/// refinement, σ of θ from the profile's curvature, status from spec's range (SolveParameter),
/// then the linear fit and prediction at θ. feature(θ, i, c, x) fills the p features of row i,
/// channel c; it may cache what depends on θ only.
template <class Feature>
SeparableSolution SolveSeparable(const Context& cx, const Series& target, const ParamSpec& spec,
                                 int p, Feature feature, const SolveOptions& opt = {}) {
  const Profile profile = [&](double coord) {
    const double theta = FromCoord(spec, coord);
    return fx::FitChannels(
               cx, target, p, [&](int i, int c, double* x) { feature(theta, i, c, x); }, nullptr)
        .sse_w;
  };
  SeparableSolution s;
  s.param = SolveParameter(spec, profile, opt);
  const double theta = s.param.value;
  s.linear = fx::FitChannels(
      cx, target, p, [&](int i, int c, double* x) { feature(theta, i, c, x); }, &s.pred);
  return s;
}

}  // namespace ftstack::diag
