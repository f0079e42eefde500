// ftd's replay backend (--adc replay): a recording's bridge columns played as the counts of the
// calibration's converter, read in the unit the calibration's recorded_unit rule decides.
#pragma once

#include <memory>

#include "daemon/backend.hpp"
#include "daemon/options.hpp"

namespace ftstack::daemon {

/// The backend of `--adc replay --replay REC.csv --cal CAL.json`: REC.csv's b* columns (and
/// temp_C) are read in the unit the recording or opt.replay_units declares, else the one CAL.json
/// was fitted from (cal::PrepareApplyInput, as ftcal apply), converted to counts of CAL.json's
/// converter and delivered at opt.rate_hz (paced, or as fast as read with opt.paced false); the
/// end of the recording ends sampling. Prints on stderr which unit was used and what decided it.
/// Throws FtdError with one line (FILE:LINE of a conflicting declaration, FILE:LINE:COLUMN of a
/// value that cannot be that unit).
[[nodiscard]] std::unique_ptr<AdcBackend> MakeReplayBackend(const FtdOptions& opt);

}  // namespace ftstack::daemon
