// Declared input units on the calibration path: the converter a fit is made for, and the
// conversion (with range refusal) of a recording's bridge columns into a calibration's input unit.
#pragma once

#include <string>

#include "calibration/file/cal_file.hpp"
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

/// The ADC (rails in signed counts = code − zero code; full scale in `unit` × 1e6 at
/// max_counts) of a described converter; `unit` is "mV/V" when the converter's scale is known,
/// else "counts" (one count per input unit).
[[nodiscard]] hal::AdcInfo AdcOfConverter(const Converter& c, double excitation_v,
                                          std::size_t channels, std::string* unit);

/// Prepares `rec` for a fit: resolves its declared unit (metadata and `cli`), refuses any bridge
/// value outside the converter's range (the declared one, else `assumed` in mV/V) with one line
/// naming file:line:column, and converts the b* columns in place into the calibration's unit.
[[nodiscard]] FitInput PrepareFitInput(Recording* rec, const UnitOverrides& cli,
                                       const hal::AdcInfo& assumed);

/// The unit of `rec`'s bridge columns for applying `cal`: what the recording or `cli` declares;
/// where nothing does, the unit and converter the calibration was fitted from (its
/// recording_unit and converter); the format default (mV/V) only when neither says. Throws
/// RecordingError (FILE:LINE of the declaration, or the option) when the declaration differs
/// from the calibration's.
[[nodiscard]] InputUnit UnitForCalibration(const Recording& rec, const UnitOverrides& cli,
                                           const CalFile& cal, const std::string& cal_path);

/// Prepares `rec` for ApplyCalibration(cal, …): resolves its unit (UnitForCalibration), converts
/// the b* columns into cal.input_unit and refuses codes that are not whole numbers and values
/// outside cal.adc's rails. Returns one line saying which unit was used and which source
/// decided it.
[[nodiscard]] std::string PrepareApplyInput(Recording* rec, const UnitOverrides& cli,
                                            const CalFile& cal, const std::string& cal_path);

/// Writes the converter and the input unit into `file` (input_unit and extra["converter"]).
void RecordInputUnit(const FitInput& in, CalFile* file);

}  // namespace ftstack::cal
