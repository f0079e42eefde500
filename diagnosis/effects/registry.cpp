// The effect plug-ins, in the vocabulary's order: one line per family, X(Family) for the plug-in
// `EffectSpec FamilyPlugin()` defined at the end of its family's file (effects/zero_offset.cpp, …:
// its kind, traits, fit functions and declared parameters). A new family is one new file and one
// line here.
#include <vector>

#include "diagnosis/engine/effect.hpp"

namespace ftstack::diag {

#define FTSTACK_EFFECT_FAMILIES(X) \
  X(ZeroOffset)                    \
  X(ZeroDrift)                     \
  X(ThermalZeroDrift)              \
  X(ThermalSpanDrift)              \
  X(ExcitationDrift)               \
  X(Creep)                         \
  X(Hysteresis)                    \
  X(BridgeNonlinearity)            \
  X(GeometricNonlinearity)         \
  X(LoadStiffening)                \
  X(Misalignment)                  \
  X(GainError)                     \
  X(TimeSkew)                      \
  X(Saturation)                    \
  X(OverloadShift)                 \
  X(MainsInterference)             \
  X(Resonance)                     \
  X(ConverterGlitch)

#define FTSTACK_DECLARE_PLUGIN(Family) EffectSpec Family##Plugin();
FTSTACK_EFFECT_FAMILIES(FTSTACK_DECLARE_PLUGIN)
#undef FTSTACK_DECLARE_PLUGIN

const std::vector<EffectSpec>& Effects() {
#define FTSTACK_PLUGIN(Family) Family##Plugin(),
  static const std::vector<EffectSpec> kEffects = {FTSTACK_EFFECT_FAMILIES(FTSTACK_PLUGIN)};
#undef FTSTACK_PLUGIN
  return kEffects;
}

}  // namespace ftstack::diag
