#include "measurement/effect_vocabulary.hpp"

#include <stdexcept>

namespace ftstack {
namespace {

constexpr bool InKindOrder() {
  for (std::size_t i = 0; i < kEffectVocabulary.size(); ++i) {
    if (static_cast<std::size_t>(kEffectVocabulary[i].kind) != i) return false;
  }
  return true;
}
static_assert(InKindOrder(), "kEffectVocabulary must list the effects in EffectKind order");

constexpr bool KeysUnique() {
  for (const auto& def : kEffectVocabulary) {
    for (std::size_t i = 0; i < def.params.size(); ++i) {
      for (std::size_t j = 0; j < def.params.size(); ++j) {
        const auto& a = def.params[i];
        const auto& b = def.params[j];
        if (i != j && (a.key == b.key || (!b.alias.empty() && a.key == b.alias))) return false;
      }
    }
  }
  return true;
}
static_assert(KeysUnique(), "an effect's keys and aliases must be distinct");

}  // namespace

const EffectDef* FindEffect(std::string_view name) {
  for (const auto& def : kEffectVocabulary) {
    if (def.name == name) return &def;
  }
  return nullptr;
}

const EffectParam* FindParam(const EffectDef& def, std::string_view key, bool accept_alias) {
  for (const auto& p : def.params) {
    if (p.key == key || (accept_alias && !p.alias.empty() && p.alias == key)) return &p;
  }
  return nullptr;
}

std::string_view ParamKey(EffectKind kind, std::string_view key, unsigned roles) {
  const EffectDef& def = EffectOf(kind);
  const EffectParam* p = FindParam(def, key, false);
  if (p == nullptr || (p->roles & roles) != roles) {
    throw std::logic_error("effect vocabulary: " + std::string(def.name) + " has no parameter '" +
                           std::string(key) + "' with that role (keys: " + ValidKeys(def, roles) +
                           ")");
  }
  return p->key;
}

std::string ValidKeys(const EffectDef& def, unsigned roles) {
  std::string out;
  for (const auto& p : def.params) {
    if ((p.roles & roles) == 0) continue;
    if (!out.empty()) out += ", ";
    out += p.key;
    if (!p.alias.empty()) out += " (alias " + std::string(p.alias) + ")";
  }
  return out.empty() ? "none" : out;
}

std::string EffectNameList() {
  std::string out;
  for (const auto& def : kEffectVocabulary) {
    if (!out.empty()) out += ", ";
    out += def.name;
  }
  return out;
}

}  // namespace ftstack
