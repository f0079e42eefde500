#include "diagnosis/engine/effect.hpp"

namespace ftstack::diag {

std::optional<EffectFit> FitNear(const EffectSpec& spec, const Context& cx, const Series& target,
                                 const EffectFit* near, bool uncertainty) {
  if (spec.refit != nullptr && near != nullptr && near->name == spec.name) {
    std::optional<EffectFit> fit = spec.refit(cx, target, *near, uncertainty);
    if (fit) fit->sigma_computed = uncertainty;
    return fit;
  }
  return spec.fit(cx, target);
}

const EffectSpec* FindEffect(const std::string& name) {
  for (const auto& e : Effects()) {
    if (name == e.name) return &e;
  }
  return nullptr;
}

const EffectSpec* FindEffectWith(unsigned traits) {
  for (const auto& e : Effects()) {
    if ((e.traits & traits) == traits) return &e;
  }
  return nullptr;
}

bool HasTrait(const EffectFit& fit, unsigned trait) {
  const EffectSpec* spec = FindEffect(fit.name);
  return spec != nullptr && spec->Has(trait);
}

}  // namespace ftstack::diag
