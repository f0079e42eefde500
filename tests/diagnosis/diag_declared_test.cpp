// The registry walked, not audited: every effect that searches declares the range of what it
// searches, with the reason for each end and a unit from the vocabulary.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/solve.hpp"
#include "diagnosis/report/json_report.hpp"
#include "tests/diagnosis/diag_fixture.hpp"

namespace ftstack::diag {
namespace {

constexpr double kNoise = 1e-4;

/// Whether [lo, hi] lies inside a declared range (to rounding).
bool Inside(const ParamSpec& p, double lo, double hi) {
  const double tol = 1e-9 * std::max(std::fabs(p.lo), std::fabs(p.hi));
  return lo >= p.lo - tol && hi <= p.hi + tol;
}

/// The declared parameters of `spec` for its fit on `cx` (its variant's where it has one).
std::vector<ParamSpec> Declared(const Context& cx, const EffectSpec& spec,
                                const std::optional<EffectFit>& fit) {
  std::vector<ParamSpec> out = spec.ranges != nullptr ? spec.ranges(cx) : std::vector<ParamSpec>{};
  if (fit) {
    const std::vector<ParamSpec> of_fit = DeclaredParams(cx, *fit, spec);
    out.insert(out.end(), of_fit.begin(), of_fit.end());
  }
  return out;
}

/// Each registered effect fitted to a fixture holding it (8 noise σ; converter_glitch, which the
/// fixture cannot inject, to noise): the engine's search log says what it searched. An effect that
/// searched declares ranges; each declared parameter has a finite range with a reason for each end
/// and is a parameter of the effect's vocabulary entry (its unit); each one-parameter solve is of a
/// declared key, and each joint search stays inside a declared range.
TEST(DiagDeclared, EveryEffectThatSearchesDeclaresTheRangeOfWhatItSearches) {
  int searching = 0;
  for (const EffectSpec& spec : Effects()) {
    const std::string name = spec.name;
    SCOPED_TRACE(name);
    std::vector<testing::FixtureEffect> injected;
    if (name != "converter_glitch") injected.push_back({name, 8.0});
    const auto fx = testing::MakeFixture(injected, 5, 200.0, kNoise, 4.0);
    const Context cx = MakeContext(fx.data);
    std::optional<EffectFit> fit;
    std::vector<SearchedRange> searched;
    {
      const SearchLog log;
      fit = spec.fit(cx, cx.resid);
      searched = log.Ranges();
    }
    if (searched.empty()) continue;
    ++searching;
    ASSERT_NE(spec.ranges, nullptr) << name << " searches without declaring its ranges";
    const std::vector<ParamSpec> declared = Declared(cx, spec, fit);
    for (const ParamSpec& p : declared) {
      EXPECT_TRUE(std::isfinite(p.lo) && std::isfinite(p.hi) && p.lo < p.hi) << p.key;
      EXPECT_STRNE(p.lo_what, "") << p.key;
      EXPECT_STRNE(p.hi_what, "") << p.key;
      EXPECT_NE(FindParam(EffectOf(spec.kind), p.key, false), nullptr)
          << p.key << " is not a parameter of " << name << " in the vocabulary";
    }
    for (const SearchedRange& s : searched) {
      bool found = false;
      for (const ParamSpec& p : declared) {
        found = found || (s.key.empty() ? p.scale == ParamScale::kLog && Inside(p, s.lo, s.hi)
                                        : s.key == p.key);
      }
      EXPECT_TRUE(found) << "searched " << (s.key.empty() ? "a coordinate" : s.key) << " in ["
                         << s.lo << ", " << s.hi << "], which no declared range holds";
    }
  }
  // Not vacuous: the effects known to search (creep, hysteresis, misalignment, time skew,
  // saturation, overload shift, mains, resonance, thermal lag) did on their fixtures.
  EXPECT_GE(searching, 8);
}

/// Every key of every effect's, candidate's and finding's `params` in a JSON report has a typed
/// `parameters` entry whose unit is the vocabulary's for that effect.
void ExpectEveryParamTyped(const nlohmann::json& report, const std::string& what) {
  int checked = 0;
  for (const char* section : {"effects", "candidates", "findings"}) {
    for (const auto& e : report[section]) {
      const std::string name = e["name"].get<std::string>();
      const EffectDef* def = ::ftstack::FindEffect(std::string_view(name));
      ASSERT_NE(def, nullptr) << what << ": " << name;
      // A candidate carries only `parameters`: each entry is checked for its fields and unit.
      nlohmann::json params = e.contains("params") ? e["params"] : nlohmann::json::object();
      if (!e.contains("params")) {
        for (const auto& p : e["parameters"]) params[p["key"].get<std::string>()] = p["value"];
      }
      for (const auto& [key, value] : params.items()) {
        const nlohmann::json* typed = nullptr;
        for (const auto& p : e["parameters"]) {
          if (p["key"] == key) typed = &p;
        }
        ASSERT_NE(typed, nullptr) << what << ": " << section << " " << name << "." << key
                                  << " has no parameters entry";
        const EffectParam* vocab = FindParam(*def, key, false);
        ASSERT_NE(vocab, nullptr) << what << ": " << name << "." << key << " not in the vocabulary";
        EXPECT_EQ((*typed)["unit"], std::string(vocab->unit)) << what << ": " << name << "." << key;
        EXPECT_EQ((*typed)["value"], value) << what << ": " << name << "." << key;
        for (const char* field : {"sigma", "range", "spread", "status"}) {
          EXPECT_TRUE(typed->contains(field)) << what << ": " << name << "." << key << " " << field;
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 0) << what;
}

// Closed-form fixtures whose reports carry counts, per-level tables and labels (zero drift's
// knots and levels, excitation drift's knots, load stiffening's terms) beside fitted numbers.
TEST(DiagDeclared, EveryReportedParameterIsTypedWithItsVocabularyUnit) {
  for (const char* name : {"zero_drift", "excitation_drift", "load_stiffening", "creep"}) {
    const auto fx = testing::MakeFixture({{name, 8.0}}, 3, 200.0, kNoise, 4.0);
    const Report r = Diagnose(fx.data);
    ExpectEveryParamTyped(ToJson(r), name);
  }
}

}  // namespace
}  // namespace ftstack::diag
