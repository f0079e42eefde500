// measurement/effect_vocabulary: the table's invariants and its lookups, against the normative
// list of docs/spec/diagnosis.md.
#include "measurement/effect_vocabulary.hpp"

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace ftstack {
namespace {

TEST(EffectVocabulary, NamesAreTheSpecsInOrder) {
  // docs/spec/diagnosis.md, "Effect vocabulary" (undetermined is a verdict only).
  const std::vector<std::string> spec = {"none",
                                         "zero_offset",
                                         "zero_drift",
                                         "thermal_zero_drift",
                                         "thermal_span_drift",
                                         "excitation_drift",
                                         "creep",
                                         "hysteresis",
                                         "bridge_nonlinearity",
                                         "geometric_nonlinearity",
                                         "load_stiffening",
                                         "misalignment",
                                         "gain_error",
                                         "time_skew",
                                         "saturation",
                                         "overload_shift",
                                         "mains_interference",
                                         "resonance",
                                         "converter_glitch"};
  ASSERT_EQ(kEffectVocabulary.size(), spec.size());
  for (std::size_t i = 0; i < spec.size(); ++i) {
    EXPECT_EQ(kEffectVocabulary[i].name, spec[i]);
    EXPECT_EQ(static_cast<std::size_t>(kEffectVocabulary[i].kind), i);
    EXPECT_EQ(FindEffect(spec[i]), &kEffectVocabulary[i]);
  }
  EXPECT_EQ(FindEffect("undetermined"), nullptr);
  EXPECT_EQ(FindEffect("Creep"), nullptr);
}

TEST(EffectVocabulary, ReportedParametersAreTheSpecsColumn) {
  // "params the report must carry" in docs/spec/diagnosis.md (and the per-channel parameters the
  // report adds: creep fraction, mains amplitude_mvv, resonance participation).
  const std::vector<std::pair<EffectKind, std::string>> want = {
      {EffectKind::kZeroOffset, "offset"},
      {EffectKind::kThermalZeroDrift, "coef_per_K"},
      {EffectKind::kThermalSpanDrift, "coef_per_K"},
      {EffectKind::kCreep, "tau_s, fraction, tau1_s, tau2_s, fraction1, fraction2"},
      {EffectKind::kBridgeNonlinearity, "channels"},
      {EffectKind::kMisalignment, "axis, angle_deg"},
      {EffectKind::kGainError, "channels, gain"},
      {EffectKind::kTimeSkew, "delay_s"},
      {EffectKind::kSaturation, "limit"},
      {EffectKind::kOverloadShift, "onset_s, recovery_tau_s, recovering_shift"},
      {EffectKind::kMainsInterference, "freq_hz, amplitude_mvv (alias amplitude)"},
      {EffectKind::kResonance,
       "freq_hz, damping_ratio, participation, freq2_hz, damping_ratio2, participation2"},
      {EffectKind::kHysteresis, "none"},
      {EffectKind::kConverterGlitch, "count, times_s"},
  };
  for (const auto& [kind, keys] : want) {
    EXPECT_EQ(ValidKeys(EffectOf(kind), kReported), keys) << EffectOf(kind).name;
  }
}

TEST(EffectVocabulary, KeysCarryUnitsAndAliasesResolve) {
  std::set<std::string> units;
  for (const auto& def : kEffectVocabulary) {
    for (const auto& p : def.params) {
      EXPECT_FALSE(p.meaning.empty()) << def.name << "." << p.key;
      EXPECT_NE(p.roles & (kBoth | kDescribed), 0U) << def.name << "." << p.key;
      const std::string key(p.key);
      // A key ending in a unit suffix declares that unit.
      if (key.ends_with("_s")) {
        EXPECT_EQ(p.unit, "s") << key;
      }
      if (key.ends_with("_hz")) {
        EXPECT_EQ(p.unit, "Hz") << key;
      }
      if (key.ends_with("_deg")) {
        EXPECT_EQ(p.unit, "deg") << key;
      }
      if (key.ends_with("_mvv") && !key.ends_with("_per_mvv")) {
        EXPECT_EQ(p.unit, "mV/V") << key;
      }
      units.insert(std::string(p.unit));
    }
  }
  EXPECT_TRUE(units.count("mV/V/K"));
  const EffectDef& mains = EffectOf(EffectKind::kMainsInterference);
  ASSERT_NE(FindParam(mains, "amplitude"), nullptr);
  EXPECT_EQ(FindParam(mains, "amplitude")->key, "amplitude_mvv");
  EXPECT_EQ(FindParam(mains, "amplitude", false), nullptr);
  EXPECT_EQ(FindParam(mains, "nope"), nullptr);
  EXPECT_EQ(ParamKey(EffectKind::kCreep, "tau_s", kBoth), "tau_s");
  EXPECT_THROW((void)ParamKey(EffectKind::kCreep, "amplitude", kReported), std::logic_error);
  // channels is the injector's selection for creep, not a parameter the report must carry.
  EXPECT_THROW((void)ParamKey(EffectKind::kCreep, "channels", kReported), std::logic_error);
  EXPECT_EQ(ValidKeys(EffectOf(EffectKind::kNone)), "none");
  EXPECT_EQ(EffectNameList().substr(0, 23), "none, zero_offset, zero");
}

}  // namespace
}  // namespace ftstack
