// The unit a calibration reads: the converter and unit it was fitted from (recording_unit,
// converter), and the conversion of a recording's bridge columns into its input unit, refusing
// what cannot be that unit. The one rule ftcal apply/check, ftd's replay and ftdiag share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "calibration/file/cal_file.hpp"
#include "measurement/recording.hpp"
#include "measurement/units.hpp"

namespace ftstack::cal {

/// A recording's bridge value x in a calibration's input unit: (x − zero) · scale.
struct InputMap {
  double scale = 1.0;
  double zero = 0.0;
};

/// The ADC (rails in signed counts = code − zero code; full scale in `unit` × 1e6 at
/// max_counts) of a described converter; `unit` is "mV/V" when the converter's scale is known,
/// else "counts" (one count per input unit).
[[nodiscard]] hal::AdcInfo AdcOfConverter(const Converter& c, double excitation_v,
                                          std::size_t channels, std::string* unit);

/// Refuses (RecordingError FILE:LINE:COLUMN) the first b0 … b{channels−1} value of `rec` that
/// `map` takes outside `adc`'s rails (beyond half a count); `unit` is the recording's, `what` names
/// the range in the message.
void CheckMappedRails(const Recording& rec, std::size_t channels, const hal::AdcInfo& adc,
                      const InputMap& map, const std::string& unit, const std::string& what);

/// Applies `map` in place to b0 … b{channels−1}.
void ApplyInputMap(Recording* rec, std::size_t channels, const InputMap& map);

/// The unit of `rec`'s bridge columns for applying `cal`: what the recording or `cli` declares;
/// where nothing does, the unit and converter the calibration was fitted from (its
/// recording_unit and converter); the format default (mV/V) only when neither says. Throws
/// RecordingError (FILE:LINE of the declaration, or the option) when the declaration differs
/// from the calibration's.
[[nodiscard]] InputUnit UnitForCalibration(const Recording& rec, const UnitOverrides& cli,
                                           const CalFile& cal, const std::string& cal_path);

/// Prepares `rec` for the calibration `cal`: resolves its unit (UnitForCalibration), converts
/// the b* columns into cal.input_unit and refuses codes that are not whole numbers and values
/// outside cal.adc's rails. Returns one line saying which unit was used and which source
/// decided it.
[[nodiscard]] std::string PrepareApplyInput(Recording* rec, const UnitOverrides& cli,
                                            const CalFile& cal, const std::string& cal_path);

/// Counts of `adc` for `value` in the calibration's input unit (`counts_per_input` =
/// fw::CountsPerMvv(adc)): rounded to the nearest count and held at the rails.
[[nodiscard]] std::int32_t InputCounts(double value, double counts_per_input,
                                       const hal::AdcInfo& adc);

}  // namespace ftstack::cal
