// From the ranking's winners to the report's claims: a partner the data cannot identify dropped,
// refinements, spreads across pieces of the record, the engine's claim rule, and each claim's
// held-out figures and confounders.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/identifiability.hpp"

namespace ftstack::diag {

/// RMS per channel of a − b (b nullptr: of a), accumulated in double.
[[nodiscard]] Eigen::VectorXd ChannelRms(const Series& a, const Series* b = nullptr);

/// A time-based partner of a load effect that one offset per load hold or a smooth (quadratic)
/// function of the load explains as well (a misfit of the first effect's shape left as a function
/// of the load, which a time curve follows) is not claimed: the data cannot tell it from the first
/// effect's remainder. Returns the partner's
/// confounding when it stays (empty otherwise). `backfit_threads`: the threads the pair's
/// backfits just ran on side by side (CheckConfounders' rows may run on as many).
[[nodiscard]] std::vector<Confounding> DropUnidentifiedPartner(const Context& cx,
                                                               const DiagnoseOptions& options,
                                                               std::vector<EffectFit>* claimed,
                                                               std::vector<std::string>* dropped,
                                                               int backfit_threads);

/// Refines the claimed effects whose plug-in has a refine_claim, each fitted to what the other
/// claimed effects leave (ranked without it, so a refinement never wins a claim on its own): the
/// refinement replaces the claim where it applies, or with kRefineOnlyIfBetter only where it scores
/// better on the held-out rows, penalised like the ranking.
void RefineClaims(const Context& cx, std::vector<EffectFit>* claimed_effects);

/// Each claimed fit's parameter spreads across pieces of the record (PieceSpreads), each refitted
/// to what the other claimed effects leave; pieces that scatter beyond the curvature σ are said in
/// its evidence.
void SpreadClaims(Context* cx, std::vector<EffectFit>* claimed_effects);

/// Claims the engine's rule no longer lets stand once their pieces are known (NotResolved: a
/// parameter not resolved by the engine's one status rule, VerdictOf) are not
/// findings: they leave the claims for r.dropped ("not_claimed"), with the reason. At least one
/// claim is kept only when it stands (an empty list means nothing is claimed).
void DropContradictedClaims(const Context& cx, std::vector<EffectFit>* claimed,
                            std::vector<std::string>* dropped);

/// The claimed effects into the report, each with its held-out gain and confounders; the verdict.
void RecordClaims(Report& r, const DiagnoseOptions& options, std::vector<EffectFit>& claimed,
                  const std::vector<Confounding>& partner_conf);

}  // namespace ftstack::diag
