// ftdiag acceptance: simulator recordings (sim::MakeRecording, as `ftsim record --effect`) with
// every vocabulary effect concealed at 2–10 noise σ on the rig/thermal profiles, several seeds,
// `none` recordings, pairs — named, located, key parameter recovered, ≥ 70 % of the excess removed.
#include <gtest/gtest.h>

#include <cstdio>
#include <ostream>

#include "diagnosis/evaluation/scorecard.hpp"
#include "sim/effects.hpp"

namespace ftstack::diag {
namespace {

std::vector<ScoreCase> Cases() {
  // Two seeds per effect (sizes ×1 and ×0.5 of the simulator's default: ≈ 2–8 σ), 120 s records.
  std::vector<ScoreCase> all = StandardCases(2, 120.0);
  return all;
}

class DiagSim : public ::testing::TestWithParam<ScoreCase> {};

}  // namespace

// ctest lists a case by its effect and seed, not by the bytes of the struct.
void PrintTo(const ScoreCase& c, std::ostream* os) { *os << c.effect << " seed " << c.seed; }

namespace {

TEST_P(DiagSim, DiagnosesTheConcealedEffect) {
  const ScoreCase& c = GetParam();
  const ScoreResult r = RunCase(c);
  std::string named;
  for (const auto& n : r.named) named += n + " ";
  SCOPED_TRACE("case " + c.effect + " seed " + std::to_string(c.seed) + " size " +
               std::to_string(r.size_sigma) + " σ; claimed: " + named);
  // The right effect(s) named as identified. Extra effects claimed beside them are penalised by
  // the scorecard (diag_scorecard, --min-pass); here they are reported: a known over-claim remains
  // (zero_drift beside the simulator's misalignment: hold offsets do not explain it as well).
  EXPECT_TRUE(r.named_right);
  if (r.extra > 0) std::printf("note: %d extra effect(s) claimed: %s\n", r.extra, named.c_str());
  EXPECT_TRUE(r.located);
  EXPECT_TRUE(r.param_ok) << r.param << " error " << r.param_error;
  EXPECT_GE(r.excess_removed, 0.7);
}

std::string CaseName(const ::testing::TestParamInfo<ScoreCase>& i) {
  std::string n = i.param.effect + "_seed" + std::to_string(i.param.seed);
  for (auto& ch : n) {
    if (ch == '+') ch = '_';
  }
  return n;
}

INSTANTIATE_TEST_SUITE_P(Recordings, DiagSim, ::testing::ValuesIn(Cases()), CaseName);

TEST(DiagSimCoverage, EveryVocabularyNameHasCases) {
  const auto cases = Cases();
  for (const auto& name : sim::EffectNames()) {
    const auto n = std::count_if(cases.begin(), cases.end(),
                                 [&](const ScoreCase& c) { return c.effect == name; });
    EXPECT_GE(n, 2) << name;
  }
}

}  // namespace
}  // namespace ftstack::diag
