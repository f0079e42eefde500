// Running the firmware's fixed-point core over a recording (what `ftcal apply` does).
#pragma once

#include "calibration/file/cal_file.hpp"
#include "measurement/recording.hpp"

namespace ftstack::cal {

/// Converts each row's b* columns (in the file's input unit) to counts of the calibration's ADC
/// (rounded, clipped at the rails), runs fw::WrenchCore on them and returns a recording with
/// columns t,Fx,Fy,Fz,Mx,My,Mz in N and N·m (plus `status`). A `temp_C` column, where present,
/// feeds the core's temperature compensation (as m°C, like hal::AdcSample).
[[nodiscard]] Recording ApplyCalibration(const CalFile& cal, const Recording& in);

}  // namespace ftstack::cal
