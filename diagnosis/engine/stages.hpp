// The diagnosis's stages in the order engine/pipeline.cpp runs them, and each one's share of the
// progress bar (so that no stage writes a fraction of its own).
#pragma once

#include "diagnosis/engine/diagnose.hpp"

namespace ftstack::diag {

/// The stages that report progress, in pipeline order.
enum class Stage : int {
  kSplit,       ///< noise, hold-out split and location
  kCandidates,  ///< every effect fitted alone and scored on held-out rows
  kPartners,    ///< partners fitted to what each pair start leaves
  kPairs,       ///< pairs backfitted and scored
  kThird,       ///< a third effect beside a claimed pair
  kDone,
};

/// A stage's span of the progress bar, [from, to].
struct StageShare {
  double from;
  double to;
};
/// Indexed by Stage: the candidate fits take the most time, then the pairs.
inline constexpr StageShare kStageShares[] = {{0.0, 0.05},  {0.05, 0.65}, {0.65, 0.85},
                                              {0.85, 0.98}, {0.98, 1.0},  {1.0, 1.0}};

/// Reports `within` (0…1) of `stage` done through options.progress, when set.
void Progress(const DiagnoseOptions& options, Stage stage, double within, const char* what);

}  // namespace ftstack::diag
