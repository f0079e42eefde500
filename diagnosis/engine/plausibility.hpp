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

/// The engine's one rule for every effect: why `fit` is never claimed, or "" when it may be. For
/// every parameter its plug-in declares (EffectSpec::ranges), in order: at_bound or
/// not_identified by StatusOf ("tau_s = 0.30 s at its lower bound (3 samples)"; per-channel
/// values: the largest |value| above hi), then, once PieceSpreads has filled fit.spread,
/// pieces_disagree for a parameter of one sign by its physics (lo ≥ 0) whose pieces' values (of
/// its largest element) straddle zero ("not resolved: pieces disagree (fraction = -0.01, per
/// piece -0.02–0.004)"); last, a prediction within the converter's grid (WithinGrid).
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
/// record's estimate), "larger" (max of that and the curvature σ), "agree"} — "agree" false when
/// the pieces scatter over 3 × what the curvature σ allows (√pieces σ per piece). A piece whose
/// refit fails or is not resolved is left out and counted in "unresolved_pieces". cx's hold-out
/// mask is restored before returning.
void PieceSpreads(Context* cx, const Series& target, EffectFit* fit);
/// The same with a given plug-in (one the registry need not hold).
void PieceSpreads(Context* cx, const Series& target, EffectFit* fit, const EffectSpec& spec);

/// "τ per piece 28–95 s"-style words for a fit's spreads that disagree, or "".
[[nodiscard]] std::string SpreadWords(const EffectFit& fit);

/// The report's typed `parameters` of a fit (docs/spec/diagnosis.md): one object per key of
/// fit.params (a count or a label the fit chose: sigma, range and spread null, "chosen") with
/// "key",
/// "unit" (the vocabulary's, else the effect's declaration, else null), "value", "sigma" (null
/// without one), "range" ([lo, hi] from the declaration, else null), "spread" (the pieces' σ, or
/// null) with "spread_why" when null, and "status": at_bound or not_identified by the declared
/// range and σ (StatusOf), pieces_disagree when the spread says so, else resolved; a parameter
/// without a declaration and without a σ is not_identified.
[[nodiscard]] nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit);
/// The same against a given plug-in (one the registry need not hold).
[[nodiscard]] nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit,
                                             const EffectSpec& spec);

}  // namespace ftstack::diag
