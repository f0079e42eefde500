// Where real − sim exceeds the noise: the channels, the time windows and the region of the load
// that carry the excess, and the residual's spectrum.
#pragma once

#include "diagnosis/engine/diagnose.hpp"

namespace ftstack::diag {

/// Model-free location on r.cx: r.mismatch_channels (block-mean and mean-square χ² tests per
/// channel), r.windows (flagged blocks on those channels, merged) and r.load_region (the load
/// component and range where the excess is largest).
void Locate(Report& r);
/// Model-informed location after a claim (r.model set): a channel the model-free tests missed
/// joins when the claimed model removes a significant held-out χ² there; windows and the load
/// region are then located again.
void LocateByModel(Report& r);
/// r.spectrum_hz / r.spectrum_power: the residual's Welch spectrum, whitened and averaged over
/// channels.
void ReportSpectrum(Report& r);

}  // namespace ftstack::diag
