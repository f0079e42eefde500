// The effect plug-ins, one registration line per family, in the vocabulary's order.
#include <vector>

#include "diagnosis/effects/families.hpp"

namespace ftstack::diag {

using namespace fx;  // NOLINT(google-build-using-namespace): the families' fit functions
using K = EffectKind;

const std::vector<EffectSpec>& Effects() {
  static const std::vector<EffectSpec> kEffects = {
      {.kind = K::kZeroOffset, .fit = &FitZeroOffset},
      {.kind = K::kZeroDrift,
       .traits = kTimeBased | kDriftInTime | kRefineOnlyIfBetter,
       .fit = &FitZeroDrift,
       .refine_claim = &RefineWithThermalLag},
      {.kind = K::kThermalZeroDrift,
       .traits = kTimeBased | kNeedsTemperature,
       .fit = &FitThermalZeroPlain,
       .refine_claim = &RefineWithThermalLag},
      {.kind = K::kThermalSpanDrift,
       .traits = kTimeBased | kNeedsTemperature,
       .fit = &FitThermalSpan},
      {.kind = K::kExcitationDrift,
       .traits = kTimeBased,
       .fit = &FitExcitation,
       .refit = &RefitExcitation,
       .cost = 2},
      {.kind = K::kCreep, .fit = &FitBy<&CreepSearch>, .refit = &RefitBy<&CreepSearch>, .cost = 4},
      {.kind = K::kHysteresis,
       .traits = kLoadHistory,
       .fit = &FitHysteresisFamily,
       .refit = &RefitHysteresis,
       .cost = 2},
      {.kind = K::kBridgeNonlinearity, .fit = &FitBridgeNonlinearity},
      {.kind = K::kGeometricNonlinearity, .fit = &FitGeometric},
      {.kind = K::kLoadStiffening, .fit = &FitLoadStiffening},
      {.kind = K::kMisalignment, .fit = &FitMisalignment},
      {.kind = K::kGainError, .fit = &FitGainError},
      {.kind = K::kTimeSkew, .fit = &FitTimeSkew},
      {.kind = K::kSaturation, .fit = &FitSaturation},
      {.kind = K::kOverloadShift, .traits = kTimeBased, .fit = &FitOverloadShift},
      {.kind = K::kMainsInterference, .fit = &FitMains},
      {.kind = K::kResonance,
       .fit = &FitBy<&ResonanceSearch>,
       .refit = &RefitBy<&ResonanceSearch>,
       .cost = 8},
  };
  return kEffects;
}

}  // namespace ftstack::diag
