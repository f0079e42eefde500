// Ranking of the candidate effects: each alone, then pairs, then a third (internal to diagnosis/).
#pragma once

#include <Eigen/Dense>
#include <chrono>
#include <cstddef>

#include "diagnosis/engine/debug.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/stages.hpp"

namespace ftstack::diag {

/// An effect's fit with its held-out figures.
struct Scored {
  EffectFit fit;
  double hold_sse = 0.0;
  double delta = 0.0;
  double z = 0.0;
  double score = 0.0;
  bool significant = false;     ///< held-out z and score pass the claim thresholds
  bool eligible = false;        ///< significant and resolved (NotResolved): may be claimed
  double hold_rms_after = 0.0;  ///< held-out RMS after removing the prediction

  /// Whether the prediction is held (only the pair starts keep theirs: memory).
  [[nodiscard]] bool HasPrediction() const { return fit.pred.size() > 0; }
};

/// Pairs start from at most this many of the best eligible singles (BestPair).
inline constexpr std::size_t kPairStarts = 3;
/// Partners tried with each start (the best by their score on what the start leaves).
inline constexpr std::size_t kPairPartners = 3;

/// Held-out RMS of target − pred (pred nullptr: of target), all channels, mV/V.
double HoldRms(const Context& cx, const Series& target, const Series* pred);

/// Every effect fitted alone to the residual and scored on the held-out rows, best first; each is
/// listed among r.candidates. The fits run in parallel (options.threads); the result does not
/// depend on their number. Only the kPairStarts best eligible fits keep their predictions.
std::vector<Scored> FitSingles(Report& r, const DiagnoseOptions& options, const Sums& base);

/// Pairs: forward selection from each of the three best eligible singles: every other effect is
/// fitted to what the first leaves, the best partners are kept, each pair is backfitted and scored
/// on the held-out rows. True with *pa, *pb set when a pair beats every model so far (the best
/// penalised held-out score among the qualifying pairs; independent of the thread count).
/// *backfit_threads gets the threads the backfits ran on side by side.
bool BestPair(const Context& cx, const DiagnoseOptions& options, std::vector<Scored>& singles,
              const Sums& base, EffectFit* pa, EffectFit* pb, int* backfit_threads);

/// The significant singles' fits, without their predictions (the growth stage's starting points).
std::vector<EffectFit> SignificantFits(std::vector<Scored>& singles);

/// Growth: a third effect beside a claimed pair. Every other significant single is refitted near
/// its own fit to what the pair leaves and scored there; the kGrowthTries best that are
/// significant there are backfitted with the pair from two starts (the candidate as fitted to the
/// pair's remainder, and as fitted alone) and claimed when it adds a significant held-out
/// improvement over the pair, carries a visible share of the excess over noise, all three stay
/// resolved, and nothing confounds it beside the refitted pair (CheckConfounders). True with the
/// claims replaced by the three backfitted fits (the new one last).
bool GrowThird(const Context& cx, const DiagnoseOptions& options,
               const std::vector<EffectFit>& near, std::vector<EffectFit>* claimed);

/// The share of the held-out excess over noise a partner or a third must add (not a misfit's
/// remainder).
inline constexpr double kVisibleShare = 0.002;
/// Candidates for the third claim backfitted with the pair, best first, at most.
inline constexpr std::size_t kGrowthTries = 2;

}  // namespace ftstack::diag
