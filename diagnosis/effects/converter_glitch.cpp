// converter_glitch: isolated wrong codes of the converter. They are found and kept out of every fit
// by the engine's conditioning (engine/conditioning.hpp) before any family is fitted, and reported
// as their own finding; there is nothing left for a fit of the residual to explain.
#include <optional>

#include "diagnosis/effects/families.hpp"

namespace ftstack::diag {

namespace {

std::optional<EffectFit> NoResidualFit(const Context& /*cx*/, const Series& /*target*/) {
  return std::nullopt;
}

}  // namespace

EffectSpec ConverterGlitchPlugin() {
  return {.kind = EffectKind::kConverterGlitch, .fit = &NoResidualFit};
}

}  // namespace ftstack::diag
