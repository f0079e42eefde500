// The honesty of a fit: whether its nonlinear parameters are resolved (inside their stated range,
// off the search bounds) and how far they move across independent pieces of the record.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diagnosis/engine/context.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/solve.hpp"

namespace ftstack::diag {

/// One parameter's status by the engine's one rule (docs/spec/diagnosis.md), and why it is not
/// resolved.
struct ParamVerdict {
  ParamStatus status = ParamStatus::kResolved;
  std::string why;  ///< "" when resolved or chosen ("tau_s = 0.3 at its lower bound (…)")
  /// A figure computed from the fit (a number without a declaration and without a σ entry): its
  /// status is the first non-resolved one of the fit's other numbers that are not derived
  /// (derived_from), else resolved (computed from the linear coefficients of the fit alone).
  bool derived = false;
  std::vector<std::string> derived_from;
};
/// The status of fit.params[key]: chosen (a count or a label), at_bound (a declared parameter
/// within kOnBound of a bound or outside its range; per-channel values: the largest |value| above
/// hi), not_identified (a value that is not finite, or a σ entry that is not finite where the fit
/// computed its σ: EffectFit::sigma_computed),
/// pieces_disagree (once PieceSpreads has filled fit.spread: a parameter of one sign by its
/// declaration, lo ≥ 0, whose pieces' values of its largest element straddle zero, or, a scale
/// searched in log, differ by more than a factor 2 and 3 σ between two pieces), else resolved. A
/// declared parameter without a σ entry (a fit made without uncertainties) is judged by its range
/// and pieces.
[[nodiscard]] ParamVerdict VerdictOf(const EffectFit& fit, const std::string& key,
                                     const std::vector<ParamSpec>& declared);

/// The engine's claim rule for every effect: why `fit` is never claimed, or "" when it may be: the
/// first parameter whose VerdictOf is neither resolved nor chosen (the declared ones first, a
/// bound or a flat profile before pieces that disagree; a derived figure is judged through what
/// it is computed from), then a prediction within the converter's grid (WithinGrid).
[[nodiscard]] std::string NotResolved(const Context& cx, const EffectFit& fit);
/// The same against a given plug-in (one the registry need not hold).
[[nodiscard]] std::string NotResolved(const Context& cx, const EffectFit& fit,
                                      const EffectSpec& spec);
/// The last test of NotResolved: on a quantised record (cx.quantisation), why a fit whose
/// prediction's RMS on the fitted rows (about kGridSampleRows of them, evenly
/// strided) stays within kResolvableSteps steps on every channel is not
/// claimed, or "" (a record on no grid, or a prediction on a channel without one).
[[nodiscard]] std::string WithinGrid(const Context& cx, const EffectFit& fit);

/// The parameters `spec` declares for `fit`: EffectSpec::fit_ranges (a variant searched in
/// narrower ranges) where it has them, else EffectSpec::ranges, else none.
[[nodiscard]] std::vector<ParamSpec> DeclaredParams(const Context& cx, const EffectFit& fit,
                                                    const EffectSpec& spec);

/// Number of independent pieces PieceSpreads refits on.
inline constexpr int kSpreadPieces = 4;

/// Refits `fit` (near itself, on `target`) once per piece of the record: kSpreadPieces
/// consecutive spans of equal length, each fit reading only its span's training rows. For every
/// parameter with a σ, fit->spread[key] = {"pieces", "min", "max" (per channel for per-channel
/// parameters), "sigma" (the pieces' standard deviation / √pieces: the spread σ of the whole
/// record's estimate), "larger" (max of that and the curvature σ), "min_sigma"/"max_sigma" (the
/// own σ of the pieces giving min and max, null without one), "scatter_over_curvature" (the
/// pieces scatter over 3 × what the curvature σ allows, √pieces σ per piece), "agree" (false when
/// VerdictOf says pieces_disagree)}. A piece whose refit fails or is not resolved is left out
/// and counted in "unresolved_pieces". cx's hold-out mask is restored before returning.
void PieceSpreads(Context* cx, const Series& target, EffectFit* fit);
/// The same with a given plug-in (one the registry need not hold).
void PieceSpreads(Context* cx, const Series& target, EffectFit* fit, const EffectSpec& spec);

/// "τ per piece 28–95 s"-style words for a fit's spreads that disagree, or "".
[[nodiscard]] std::string SpreadWords(const EffectFit& fit);

/// The report's typed `parameters` of a fit (docs/spec/diagnosis.md): one object per key of
/// fit.params (a count or a label the fit chose: sigma, range and spread null, "chosen") with
/// "key", "unit" (the vocabulary's, else the effect's declaration, else null), "value", "sigma"
/// (null without one), "range" ([lo, hi] from the declaration, else null), "spread" (the pieces'
/// σ, or null) with "spread_why" when null, "status" by VerdictOf (the claim rule's), "why" when
/// not resolved, and "derived_from" for a figure computed from the fit.
[[nodiscard]] nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit);
/// The same against a given plug-in (one the registry need not hold).
[[nodiscard]] nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit,
                                             const EffectSpec& spec);

}  // namespace ftstack::diag
