// The sim-vs-real diagnosis: locate the mismatch, rank candidate effects on held-out rows, report.
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/engine/effect.hpp"
#include "diagnosis/loader/data.hpp"

namespace ftstack::diag {

struct DiagnoseOptions {
  double block_s = 0.5;  ///< length of the interleaved hold-out blocks, s
  double z_claim = 6.0;  ///< held-out significance an effect needs before it is claimed
  bool pairs = true;     ///< also try two effects at once
  int threads = 0;  ///< threads for independent fits (0: the machine's, at most 4); same result
  ProgressFn progress = nullptr;
  void* progress_user = nullptr;
};

/// One candidate as it scored on the held-out rows.
struct CandidateScore {
  std::string name;
  std::string variant;
  int n_params = 0;
  double hold_rms_after = 0.0;  ///< mV/V, all channels
  double z = 0.0;               ///< held-out improvement in units of its own standard deviation
  double score = 0.0;           ///< held-out Δχ² minus the parameter penalty
  bool eligible = false;        ///< passed the claim thresholds
  std::string not_resolved;     ///< why the fit is not resolved (NotResolved), or ""
  nlohmann::json parameters = nlohmann::json::array();  ///< TypedParameters of its fit
};

/// A claimed effect with its fitted model and held-out figures.
struct ClaimedEffect {
  EffectFit fit;
  Eigen::VectorXd
      rms_after;  ///< per channel, whole record, after removing this and earlier effects
  double hold_rms_before = 0.0;  ///< held-out RMS before this effect (after earlier ones)
  double hold_rms_after = 0.0;
  /// What the data cannot tell this effect from (identifiability.hpp); empty when identified.
  std::vector<std::string> confounded_with;
  std::string confounding;  ///< the same in words
};

struct Report {
  Context cx;  ///< residual, noise, hold-out split (points into the data)
  double rate_hz = 0.0;
  Eigen::VectorXd noise_rms;
  Eigen::VectorXd rms_before;
  std::vector<int> mismatch_channels;
  std::vector<std::pair<double, double>> windows;
  nlohmann::json load_region;  ///< null, or {component, sign, range, excess_ratio}
  /// The best-supported identified effect; "none"; or "undetermined" when every claimed effect is
  /// confounded (diagnosis.md).
  std::string verdict = "none";
  std::vector<ClaimedEffect> effects;
  std::vector<CandidateScore> candidates;  ///< every single effect tried, best score first
  /// Partners of a pair left unclaimed, with the reason (a time-based partner that one offset
  /// per load hold explains as well, diagnosis.md "not_claimed").
  std::vector<std::string> dropped;
  double hold_rms_before = 0.0;
  double hold_rms_after = 0.0;
  Series model;                        ///< n × N: the claimed effects' total prediction
  std::vector<double> spectrum_hz;     ///< residual spectrum, whitened and averaged over channels
  std::vector<double> spectrum_power;  ///< (white noise → 1)
};

/// Runs the whole diagnosis on aligned data. `data` must outlive the report.
[[nodiscard]] Report Diagnose(const DiagData& data, const DiagnoseOptions& options = {});
/// A temporary would die before the report that refers to it.
Report Diagnose(DiagData&& data, const DiagnoseOptions& options = {}) = delete;
/// The same, taking the memory of data->sim_mvv and data->real_mvv (left empty) for the context's
/// load and residual: two n × N matrices fewer (MakeContext(DiagData*)). The result is the same.
[[nodiscard]] Report Diagnose(DiagData* data, const DiagnoseOptions& options = {});
/// One pass with the given noise per channel (nullptr: the robust estimate). Diagnose() runs it
/// once more with the refined noise when the claimed model shows the first estimate too high.
[[nodiscard]] Report DiagnoseOnce(const DiagData& data, const DiagnoseOptions& options,
                                  const Eigen::VectorXd* sigma);
Report DiagnoseOnce(DiagData&& data, const DiagnoseOptions& options,
                    const Eigen::VectorXd* sigma) = delete;

}  // namespace ftstack::diag
