// What an effect is to the engine: a fitted effect (EffectFit) and its plug-in (EffectSpec).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "measurement/effect_vocabulary.hpp"

namespace ftstack::diag {

/// A fitted effect: its prediction of the residual and what to report.
struct EffectFit {
  std::string name;
  std::string variant;  ///< which parametrisation won inside the effect
  int n_params = 0;
  Series pred;  ///< n × N predicted residual, mV/V
  nlohmann::json params = nlohmann::json::object();
  nlohmann::json sigma = nlohmann::json::object();  ///< 1-σ uncertainty of params (same keys)
  /// False for a refit made without uncertainties (FitNear): its σ entries are not judged.
  bool sigma_computed = true;
  std::vector<int> channels;  ///< channels the effect acts on
  /// Figures in a standard's terms computed from the fitted shape, by standard (e.g. "oiml_r60").
  nlohmann::json standard = nlohmann::json::object();
  std::string evidence;
  double train_sse_w = 0.0;  ///< whitened training SSE after the fit
  /// The nonlinear parameters as the search left them (a RefitFn's start; not reported).
  std::vector<double> search_state;
  /// Empty when every declared parameter (EffectSpec::ranges) ended inside its range; else why the
  /// fit is not resolved (a parameter on a search bound or outside its physical range): such a
  /// fit is never claimed.
  std::string not_resolved;
  /// Per reported parameter, its spread across independent pieces of the record (PieceSpreads).
  nlohmann::json spread = nlohmann::json::object();
};

/// How the engine searches a nonlinear parameter: in log of its value (a scale, > 0) or linearly
/// (a location or a signed quantity).
enum class ParamScale { kLog, kLinear };

/// A parameter an effect declares to the engine: its key and unit, its physical range (which is
/// also its search's bounds) with the reason for each end, its search scale and its start grid. A
/// fit ending within kOnBound of a bound (in log, for positive ranges; of the range, else) or
/// outside it is not resolved and never claimed.
struct ParamSpec {
  const char* key = "";  ///< params key: a number, or per-channel numbers (their largest |value|)
  double lo = 0.0;  ///< lower bound; 0 for per-channel numbers (only |value| ≤ hi is checked)
  double hi = 0.0;  ///< upper bound
  const char* lo_what = "";  ///< the lower bound's meaning in words ("3 samples")
  const char* hi_what = "";  ///< the upper bound's ("a third of the record")
  /// Unit of the value; the vocabulary's (measurement/effect_vocabulary) wins where it has the key.
  const char* unit = "";
  ParamScale scale = ParamScale::kLog;
  int grid_points = 11;   ///< the start grid: this many points evenly over [lo, hi] in `scale`
  int golden_steps = 10;  ///< golden-section steps refining the best grid point
};
/// The declared parameters of an effect on a context (sample interval, record length, Nyquist).
using ParamSpecsFn = std::vector<ParamSpec> (*)(const Context&);
/// The declared parameters of one fit of an effect (for a variant searched in narrower ranges).
using FitSpecsFn = std::vector<ParamSpec> (*)(const Context&, const EffectFit&);

using FitFn = std::optional<EffectFit> (*)(const Context&, const Series& target);
/// Refits an effect near an earlier fit of the same effect: `near`'s nonlinear parameters start a
/// local search (a full search only when the optimum leaves the local window) and its variant
/// class is kept. The pair stage's partner fits and backfits use it: there the target differs from
/// the one `near` was fitted to by another effect's prediction, not by a new shape. Without
/// `uncertainty` the nonlinear parameters' 1-σ are not computed (null): for intermediate fits
/// whose parameters only start the next one, never for a fit that is reported.
using RefitFn = std::optional<EffectFit> (*)(const Context&, const Series& target,
                                             const EffectFit& near, bool uncertainty);

/// A claimed effect's refinement after the ranking, fitted to what the other claimed effects leave:
/// the refined fit, or nullopt where the refinement does not apply to the data.
using RefineFn = std::optional<EffectFit> (*)(const Context&, const Series& target);

/// What the engine reads about an effect instead of its name (bits of EffectSpec::traits).
enum EffectTrait : unsigned {
  kNoTraits = 0U,
  /// Its shape is a function of time (or of a temperature that may be monotone in time).
  kTimeBased = 1U << 0U,
  /// A rate-independent function of the load's history (hysteresis).
  kLoadHistory = 1U << 1U,
  /// Driven by the recorded temperature.
  kNeedsTemperature = 1U << 2U,
  /// The plain drift in time: the alternative the engine tests temperature-driven effects against.
  kDriftInTime = 1U << 3U,
  /// refine_claim replaces the claimed fit only when it scores better on the held-out rows
  /// (penalised like the ranking); without it, whenever it applies.
  kRefineOnlyIfBetter = 1U << 4U,
};

/// The alternatives a claim must beat on the held-out rows (bits of EffectSpec::confounders): the
/// rows of the engine's confounder table (identifiability.cpp), each tested where the data allow
/// it.
enum Confounder : unsigned {
  kNoConfounders = 0U,
  kSegmentOffsets = 1U << 0U,  ///< one offset per channel and joined recording (≥ 2 segments)
  kLoadOffsets = 1U << 1U,     ///< one offset per channel and distinct static load
  kHoldOffsets = 1U << 2U,     ///< one offset per channel and load hold: the load's history
  kLoadPolynomial = 1U << 3U,  ///< a quadratic polynomial of the reference wrench per channel
  /// The kDriftInTime effect, where the temperature is monotone in time.
  kTimeDrift = 1U << 4U,
};
/// What a drift in time must beat: offsets per recording, per load and per hold (a function of
/// the load and its history) and a smooth function of the load.
inline constexpr unsigned kConfoundersOfTime =
    kSegmentOffsets | kLoadOffsets | kHoldOffsets | kLoadPolynomial;
/// What a function of the load's history must beat where every load is held once: offsets per
/// recording and per load (per-hold offsets and a load polynomial are of its own kind).
inline constexpr unsigned kConfoundersOfLoadHistory = kSegmentOffsets | kLoadOffsets;

/// An effect plug-in: its kind in the vocabulary, its traits and its fit functions. Each family's
/// file defines one (`EffectSpec FamilyPlugin()`), the registry (diagnosis/effects/registry.cpp)
/// lists them; the engine knows effects only by these.
struct EffectSpec {
  EffectKind kind = EffectKind::kNone;
  unsigned traits = kNoTraits;            ///< EffectTrait bits
  unsigned confounders = kNoConfounders;  ///< Confounder bits: the table rows it must beat
  FitFn fit = nullptr;
  RefitFn refit = nullptr;  ///< nullptr: the effect has no costly search; fit() is used
  int cost = 1;  ///< relative cost of a fit: when fits run in parallel, costlier ones start first
  RefineFn refine_claim = nullptr;  ///< nullptr: a claim is reported as ranked
  /// Its nonlinear parameters (and scales with a physical range); nullptr: linear parameters only.
  ParamSpecsFn ranges = nullptr;
  /// Where a variant searches narrower ranges than `ranges`: the declared parameters of a given fit
  /// (they replace `ranges` for it); nullptr: `ranges` hold for every fit.
  FitSpecsFn fit_ranges = nullptr;
  /// The vocabulary's name of `kind` (the report's and the confounders' key).
  const char* name = EffectOf(kind).name.data();

  /// Whether the plug-in has every EffectTrait bit of `trait`.
  [[nodiscard]] bool Has(unsigned trait) const { return (traits & trait) == trait; }
};

/// spec.refit near *near when both exist, else spec.fit.
[[nodiscard]] std::optional<EffectFit> FitNear(const EffectSpec& spec, const Context& cx,
                                               const Series& target, const EffectFit* near,
                                               bool uncertainty = true);

/// Every effect of the vocabulary except `none`, in spec order (the registry).
[[nodiscard]] const std::vector<EffectSpec>& Effects();
/// The effect named `name`, or nullptr.
[[nodiscard]] const EffectSpec* FindEffect(const std::string& name);
/// The first effect with every bit of `traits`, or nullptr.
[[nodiscard]] const EffectSpec* FindEffectWith(unsigned traits);
/// Whether the effect of `fit` has `trait` (false for an effect the registry does not hold).
[[nodiscard]] bool HasTrait(const EffectFit& fit, unsigned trait);

}  // namespace ftstack::diag
