// The diagnosis scorecard: simulator recordings with concealed effects, diagnosed and judged
// against truth.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ftstack::diag {

/// One recording to make and diagnose.
struct ScoreCase {
  std::string effect;              ///< vocabulary name ("none" for noise only)
  std::vector<std::string> specs;  ///< --effect arguments (empty for none)
  std::string profile = "rig";
  std::uint64_t seed = 1;
  double factor = 1.0;  ///< size relative to the simulator's default
  double duration_s = 150.0;
};

/// How the tool did on one case, judged against the simulator's truth.
struct ScoreResult {
  ScoreCase c;
  std::string verdict;
  std::vector<std::string> named;  ///< effects the report claims
  double size_sigma = 0.0;         ///< truth: the effect's peak / noise σ
  bool detected = false;     ///< the right name(s) claimed and nothing else (none: nothing claimed)
  int extra = 0;             ///< effects claimed that the truth does not hold
  bool named_right = false;  ///< the right name(s) claimed as identified (extras allowed)
  bool located = false;      ///< channel / onset / frequency / delay / region right
  std::string param;         ///< key parameter compared ("" if the effect has none)
  double param_error = 0.0;  ///< relative (or absolute s for onset_s) error
  bool param_ok = true;
  double excess_removed = 1.0;  ///< 1 − excess_after/excess_before on held-out rows
  double seconds = 0.0;         ///< diagnosis time
  [[nodiscard]] bool passed() const {
    return detected && located && param_ok && excess_removed >= 0.7;
  }
};

/// Every vocabulary effect at sizes ×0.5, ×1, ×2 of the default over `seeds` seeds (sizes cycle
/// with the seed), plus `none` cases and the pairs and subtle cases of the proof.
[[nodiscard]] std::vector<ScoreCase> StandardCases(int seeds, double duration_s);

/// Makes the recording in-process (sim::MakeRecording), diagnoses it and judges the report.
[[nodiscard]] ScoreResult RunCase(const ScoreCase& c);

/// The docs table: one row per effect (all seeds and sizes), totals at the end.
[[nodiscard]] std::string ScorecardMarkdown(const std::vector<ScoreResult>& results,
                                            const std::string& command);

}  // namespace ftstack::diag
