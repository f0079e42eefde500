// ftd's calibration set: slots from files, --cal-dir or the backend's own; rated range; payload.
#pragma once

#include <cstdint>
#include <string>

#include "daemon/backend.hpp"
#include "daemon/options.hpp"
#include "firmware/device.hpp"

namespace ftstack::daemon {

/// CRC-32 of the fixed-point form of a calibration (little-endian: channel count, then per row
/// the N coefficients and the bias as int64 and the shift as uint8, then the rails as int32).
/// Reported in input registers 72–73 for the built-in calibration, which has no file.
[[nodiscard]] std::uint32_t FixedFormCrc(const fw::FixedCalibration& cal);

/// --cal-dir: points opt->cal/cal_b at the directory's slot files and returns the active slot
/// ('A', 'B') as CalSlots::LoadActive resolves it (0 when none is valid), logging why.
[[nodiscard]] char ResolveSlotDirectory(FtdOptions* opt);

/// Fills cfg's calibration slots, initial slot and rated range for the converter `info`: slot 0
/// from --cal (else the backend's built-in calibration), slot 1 from --cal-b. A file that cannot
/// be used leaves its slot empty with one line on stderr (the device still comes up); `dir_slot`
/// ('B') starts on slot 1. Throws FtdError when no built-in exists or the rated range is unusable.
void LoadCalibrationSet(const FtdOptions& opt, char dir_slot, AdcBackend& backend,
                        const hal::AdcInfo& info, fw::DeviceConfig* cfg);

/// Loads `path` as gravity compensation's payload into `cfg`; a refused file stops ftd (FtdError):
/// unlike a calibration, a robot relying on compensation must not run with none.
void LoadPayload(const std::string& path, fw::DeviceConfig* cfg);

}  // namespace ftstack::daemon
