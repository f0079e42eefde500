// The effect vocabulary: name → fit function, in spec order.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/common.hpp"
#include "diagnosis/signal.hpp"

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the effects' private helpers

const std::vector<EffectSpec>& Effects() {
  static const std::vector<EffectSpec> kEffects = {
      {"zero_offset", &FitZeroOffset},
      {"zero_drift", &FitZeroDrift},
      {"thermal_zero_drift", &FitThermalZeroPlain},
      {"thermal_span_drift", &FitThermalSpan},
      {"excitation_drift", &FitExcitation, &RefitExcitation, 2},
      {"creep", &FitBy<&CreepSearch>, &RefitBy<&CreepSearch>, 4},
      {"hysteresis", &FitHysteresisFamily, &RefitHysteresis, 2},
      {"bridge_nonlinearity", &FitBridgeNonlinearity},
      {"geometric_nonlinearity", &FitGeometric},
      {"load_stiffening", &FitLoadStiffening},
      {"misalignment", &FitMisalignment},
      {"gain_error", &FitGainError},
      {"time_skew", &FitTimeSkew},
      {"saturation", &FitSaturation},
      {"overload_shift", &FitOverloadShift},
      {"mains_interference", &FitMains},
      {"resonance", &FitBy<&ResonanceSearch>, &RefitBy<&ResonanceSearch>, 8},
  };
  return kEffects;
}

std::optional<EffectFit> FitNear(const EffectSpec& spec, const Context& cx, const Series& target,
                                 const EffectFit* near, bool uncertainty) {
  if (spec.refit != nullptr && near != nullptr && near->name == spec.name) {
    return spec.refit(cx, target, *near, uncertainty);
  }
  return spec.fit(cx, target);
}

const EffectSpec* FindEffect(const std::string& name) {
  for (const auto& e : Effects()) {
    if (name == e.name) return &e;
  }
  return nullptr;
}

}  // namespace ftstack::diag
