// Candidate physical effects of the diagnosis: each a parametric model of the sim-vs-real residual.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/data.hpp"

namespace ftstack::diag {

/// A per-row series of every channel (n × N, mV/V) held in single precision: the residual, the
/// fits' targets and their predictions. Memory: 4 bytes a value (at 10^6 rows × 8 channels, 32 MB
/// instead of 64 MB); the rounding, 6e-8 of the value, is far below the noise of any recording.
/// Every sum over a Series is accumulated in double.
using Series = Eigen::MatrixXf;

/// Everything the effect models share, computed once from the data.
struct Context {
  const DiagData* data = nullptr;
  int n = 0;                        ///< rows
  int nc = 0;                       ///< channels
  Series resid;                     ///< n × N real − sim, mV/V
  Eigen::VectorXd sigma;            ///< robust noise per channel, mV/V
  Eigen::VectorXd weight;           ///< 1/σ² per channel
  std::vector<std::uint8_t> train;  ///< 1 = row used for fitting, 0 = held out
  std::size_t n_train = 0;
  std::size_t n_hold = 0;
  double block_s = 0.0;        ///< length of the interleaved hold-out blocks
  Eigen::VectorXd zero;        ///< sim at zero wrench per channel (regression intercept), mV/V
  Eigen::MatrixXd load;        ///< n × N: sim − zero (the load-induced part)
  Eigen::MatrixXd sens;        ///< N × 6 sim sensitivity d(mV/V)/d(wrench) by regression
  Eigen::VectorXd load_range;  ///< per channel max − min of load, mV/V
  std::vector<double> dtemp;   ///< temp − 20 °C; empty without temperature
  bool uniform = true;         ///< sampling uniform to 1e-6 relative
  double dt = 0.0;             ///< median sample interval, s
  double rate_hz = 0.0;
  int search_stride =
      1;  ///< row step used inside nonlinear parameter searches (final fits use all)
  /// 1 at the first row of every segment after the first (DiagData::segment): stateful models
  /// restart there and hold-out blocks never straddle it. Empty for one recording.
  std::vector<std::uint8_t> restart;
  int segments = 1;             ///< number of joined recordings
  std::vector<double> peak_hz;  ///< prominent lines of the residual spectrum, strongest first
  std::vector<double> peak_ratio;

  /// The sim's output of row i, channel c, mV/V (load + zero: the data's sim_mvv may be released).
  [[nodiscard]] double sim_mvv(int i, int c) const { return load(i, c) + zero(c); }
};

/// Builds the context: residual, noise, hold-out blocks (every third block of ~block_s).
/// `sigma` (one per channel), when given, replaces the robust noise estimate.
[[nodiscard]] Context MakeContext(const DiagData& d, double block_s = 0.5,
                                  const Eigen::VectorXd* sigma = nullptr);
/// The same, taking the memory of d->real_mvv and d->sim_mvv for the residual and the load (both
/// are left empty; d->released_channels keeps their width). Memory: two n × N matrices fewer.
[[nodiscard]] Context MakeContext(DiagData* d, double block_s = 0.5,
                                  const Eigen::VectorXd* sigma = nullptr);
/// Replaces the context's noise per channel (and what depends on it: weights, spectral lines);
/// the same as MakeContext with `sigma`, without the data's bridge matrices.
void SetNoise(Context* cx, const Eigen::VectorXd& sigma);

/// A fitted effect: its prediction of the residual and what to report.
struct EffectFit {
  std::string name;
  std::string variant;  ///< which parametrisation won inside the effect
  int n_params = 0;
  Series pred;  ///< n × N predicted residual, mV/V
  nlohmann::json params = nlohmann::json::object();
  nlohmann::json sigma = nlohmann::json::object();  ///< 1-σ uncertainty of params (same keys)
  std::vector<int> channels;                        ///< channels the effect acts on
  /// Figures in a standard's terms computed from the fitted shape, by standard (e.g. "oiml_r60").
  nlohmann::json standard = nlohmann::json::object();
  std::string evidence;
  double train_sse_w = 0.0;  ///< whitened training SSE after the fit
  /// The nonlinear parameters as the search left them (a RefitFn's start; not reported).
  std::vector<double> search_state;
};

using FitFn = std::optional<EffectFit> (*)(const Context&, const Series& target);
/// Refits an effect near an earlier fit of the same effect: `near`'s nonlinear parameters start a
/// local search (a full search only when the optimum leaves the local window) and its variant
/// class is kept. The pair stage's partner fits and backfits use it: there the target differs from
/// the one `near` was fitted to by another effect's prediction, not by a new shape. Without
/// `uncertainty` the nonlinear parameters' 1-σ are not computed (null): for intermediate fits
/// whose parameters only start the next one, never for a fit that is reported.
using RefitFn = std::optional<EffectFit> (*)(const Context&, const Series& target,
                                             const EffectFit& near, bool uncertainty);

struct EffectSpec {
  const char* name;
  FitFn fit;
  RefitFn refit = nullptr;  ///< nullptr: the effect has no costly search; fit() is used
  int cost = 1;  ///< relative cost of a fit: when fits run in parallel, costlier ones start first
};

/// spec.refit near *near when both exist, else spec.fit.
[[nodiscard]] std::optional<EffectFit> FitNear(const EffectSpec& spec, const Context& cx,
                                               const Series& target, const EffectFit* near,
                                               bool uncertainty = true);

/// Every effect of the vocabulary except `none`, in spec order.
[[nodiscard]] const std::vector<EffectSpec>& Effects();
/// The effect named `name`, or nullptr.
[[nodiscard]] const EffectSpec* FindEffect(const std::string& name);

/// thermal_zero_drift against a given temperature history dtemp (°C from 20 °C, one per row):
/// r_c = a_c + k_c·dtemp (effects.cpp).
[[nodiscard]] std::optional<EffectFit> FitThermalZeroOn(const Context& cx, const Series& target,
                                                        const std::vector<double>& dtemp);
/// thermal_zero_drift with a first-order lag τ ≥ 0 between the thermometer and the gauges:
/// dtemp is replaced by LP_τ[dtemp] (restarting per segment), τ found by grid + golden search on
/// the training rows (effects/thermal_lag.cpp).
[[nodiscard]] std::optional<EffectFit> FitThermalZeroLagged(const Context& cx,
                                                            const Series& target);

/// hysteresis as one rate-independent operator (Dahl or play, width searched) per bridge.
[[nodiscard]] std::optional<EffectFit> FitHysteresisOperator(const Context& cx,
                                                             const Series& target);
/// hysteresis in the load path: one operator (Dahl or play, width searched) or a
/// Prandtl–Ishlinskii sum of plays of fixed widths on each reference wrench axis, mapped to the
/// bridges by the sensitivity cx.sens (effects/hysteresis_axes.cpp).
[[nodiscard]] std::optional<EffectFit> FitHysteresisAxes(const Context& cx, const Series& target);
/// hysteresis of general rate-independent shape: the one-operator fit or a Preisach superposition
/// of relays (thresholds on 8 quantiles of each bridge's load, weights fitted per bridge; this
/// class contains Prandtl–Ishlinskii sums of play operators), whichever has the lower training
/// BIC (effects/hysteresis_pi.cpp).
[[nodiscard]] std::optional<EffectFit> FitHysteresisFamily(const Context& cx, const Series& target);
/// hysteresis refitted near an earlier fit (RefitFn): only the sub-family (load-path operators,
/// one operator per bridge, or Preisach per bridge) that fit came from.
[[nodiscard]] std::optional<EffectFit> RefitHysteresis(const Context& cx, const Series& target,
                                                       const EffectFit& near, bool uncertainty);

/// Whitened sums over train or hold-out rows.
struct Sums {
  double train_sse = 0.0;
  double hold_sse = 0.0;
  double hold_pp = 0.0;  ///< Σ (pred)²/σ² on hold-out rows
};
[[nodiscard]] Sums Score(const Context& cx, const Series& target, const Series* pred);
/// Score(cx, target, &(a + b)) without the n × N sum (the same sums, element by element).
[[nodiscard]] Sums ScoreSum(const Context& cx, const Series& target, const Series& a,
                            const Series& b);

}  // namespace ftstack::diag
