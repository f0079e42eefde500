// Identifiability of time-based effects: tests a claimed drift in time against what the data
// cannot tell it from (per-segment offsets, a function of the load, temperature versus time).
#pragma once

#include <string>
#include <vector>

#include "diagnosis/engine/effect.hpp"

namespace ftstack::diag {

/// What a claimed effect could not be told apart from.
struct Confounding {
  std::vector<std::string> with;  ///< "segment_offsets", "load_function", "hold_offsets",
                                  ///< "load_polynomial", or the name of the drift in time
  std::string words;              ///< one sentence for a person
};

/// Tests `fit` (fitted to `target`) against the confounders its effect declares
/// (EffectSpec::confounders, rows of the engine's table): the confounder and the effect are
/// fitted jointly (backfitting, training rows only), and the effect is confounded with it when the
/// joint model does not beat the confounder alone on the held-out rows significantly (z at most
/// `z_claim`) although the confounder alone, penalised for its parameters like the ranking
/// (Δχ² − p·ln n_hold), scores at least as well as the effect's penalised score. The rows:
///  - kSegmentOffsets ("segment_offsets"): one offset per channel and joined recording (≥ 2);
///  - kLoadOffsets ("load_function"): one offset per channel and distinct static load (the wrench
///    quantised to 0.5 % of each axis's range; only where loads are held, ≤ rows/20 loads);
///  - kHoldOffsets ("hold_offsets"): one offset per channel and load hold (a run of ≥ 0.25 s at
///    one load, with the movement into it): any function of the load's history. Where the effect
///    lies within those offsets (were it exact, its held-out gain beyond them would not reach
///    z_claim: e.g. a level per stretch between load changes), they are tested as the function of
///    the load's history they stand for: one offset per load state (a hold's load and the
///    previous hold's), which holds reached the same way at different levels refute; an effect
///    with fewer parameters than the holds' offsets is still identified by the penalised
///    comparison;
///  - kLoadPolynomial ("load_polynomial"): a quadratic polynomial of the reference wrench per
///    channel (28 terms): a smooth function of the load, ramps included;
///  - kTimeDrift (the kDriftInTime effect, reported by its name): where the temperature is
///    monotone in time (|Spearman ρ| > 0.95).
/// The table's rows are tested side by side on the context's threads while their extra bytes fit
/// the side-by-side budget (parallel.hpp), and on at least `backfit_threads` (up to the
/// context's): the caller checks right after backfits that ran on that many threads side by side,
/// each holding about as many n × N series as a row does, so the rows reuse the heap those grew.
/// The result does not depend on the threads.
[[nodiscard]] Confounding CheckConfounders(const Context& cx, const Series& target,
                                           const EffectFit& fit, double z_claim,
                                           int backfit_threads = 0);

/// Group of every row for an offset confounder (kSegmentOffsets, kLoadOffsets, kHoldOffsets);
/// empty when it does not apply to the data. *groups receives the number of groups.
[[nodiscard]] std::vector<int> ConfounderGroups(const Context& cx, Confounder which, int* groups);

}  // namespace ftstack::diag
