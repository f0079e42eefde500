// Declared input units on the calibration path: the converter a fit is made for, and the
// conversion (with range refusal) of a recording's bridge columns into a calibration's input unit.
#pragma once

#include <string>

#include "calibration/file/cal_file.hpp"
#include "calibration/file/recorded_unit.hpp"
#include "measurement/recording.hpp"
#include "measurement/units.hpp"

namespace ftstack::cal {

/// What a fit works in, and the ADC its fixed-point form is made for.
struct FitInput {
  InputUnit declared;       ///< the recording's unit as declared (or the format default)
  std::string cal_unit;     ///< input unit of the calibration: "mV/V" or "counts"
  hal::AdcInfo adc{};       ///< rails and full scale (cal_unit at max_counts, × 1e6)
  std::string description;  ///< one line for the user: unit, source, converter
};

/// Prepares `rec` for a fit: resolves its declared unit (metadata and `cli`), refuses any bridge
/// value outside the converter's range (the declared one, else `assumed` in mV/V) with one line
/// naming file:line:column, and converts the b* columns in place into the calibration's unit.
[[nodiscard]] FitInput PrepareFitInput(Recording* rec, const UnitOverrides& cli,
                                       const hal::AdcInfo& assumed);

/// Writes the converter and the input unit into `file` (input_unit and extra["converter"]).
void RecordInputUnit(const FitInput& in, CalFile* file);

}  // namespace ftstack::cal
