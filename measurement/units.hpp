// Declared units of a recording's bridge columns (mV/V, volts, raw converter counts): parsing,
// conversion to mV/V, the converter's rails, and the range check that refuses what cannot be.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "measurement/recording.hpp"

namespace ftstack {

/// What the numbers in the b* columns are.
enum class BridgeUnit : std::uint8_t {
  kMvv = 0,  ///< bridge output / excitation × 1000 (the format's default)
  kVolts,    ///< bridge output in V (needs the excitation to become mV/V)
  kCounts,   ///< raw codes of a described converter
};

/// How a converter's codes map to signed input.
enum class AdcCoding : std::uint8_t {
  kSigned = 0,    ///< two's complement: −2^(B−1) … 2^(B−1)−1, zero input at code 0
  kUnsigned,      ///< 0 … 2^B−1, zero input at code 0 (unipolar)
  kOffsetBinary,  ///< 0 … 2^B−1, zero input at code 2^(B−1)
};

/// A described analogue-to-digital converter. The size of one code (LSB) at the converter input
/// is reference_v / 2^B (unsigned) or reference_v / 2^(B−1) (signed, offset-binary); the bridge
/// sees that divided by `gain`. With `ratiometric` the reference is reference_ratio × the
/// excitation, so the excitation cancels; otherwise reference_v and the excitation are needed.
/// `full_scale_mvv` states the result directly: the bridge input (mV/V) worth `reference`.
struct Converter {
  int bits = 0;  ///< resolution, 2 … 31
  AdcCoding coding = AdcCoding::kSigned;
  double gain = 1.0;             ///< PGA gain in front of the converter
  bool ratiometric = true;       ///< reference derived from the bridge excitation
  double reference_ratio = 1.0;  ///< reference / excitation when ratiometric
  double reference_v = 0.0;      ///< reference voltage when not ratiometric, V (0 = unknown)
  double full_scale_mvv = 0.0;   ///< bridge input worth the reference, mV/V (0 = from the above)
};

/// The unit of a recording's b* columns and where it was declared.
struct InputUnit {
  BridgeUnit unit = BridgeUnit::kMvv;
  bool has_converter = false;  ///< `converter` is meaningful (required for kCounts)
  Converter converter{};
  double excitation_v = 0.0;              ///< bridge excitation, V (0 = not declared)
  std::string source = "format default";  ///< "format default", "metadata", "command line"
};

/// Declarations given on a command line (empty strings: not given).
struct UnitOverrides {
  std::string unit;       ///< --bridge-unit mV/V | V | counts
  std::string converter;  ///< --converter "bits=10,coding=unsigned,…"
  double excitation_v = 0.0;
};

/// Parses "mV/V", "V" (also "volts"), "counts"; throws std::invalid_argument otherwise.
[[nodiscard]] BridgeUnit ParseBridgeUnit(const std::string& text);
[[nodiscard]] const char* ToString(BridgeUnit unit);
[[nodiscard]] const char* ToString(AdcCoding coding);
/// Parses "bits=10, coding=unsigned, gain=1, ratiometric=yes, reference_ratio=1,
/// reference_v=…, full_scale_mvv=…" (keys in any order, bits required). Throws
/// std::invalid_argument naming `where` and the offending key.
[[nodiscard]] Converter ParseConverter(const std::string& text, const std::string& where);
/// The same description as ParseConverter reads.
[[nodiscard]] std::string FormatConverter(const Converter& c);

/// The unit of `rec`'s bridge columns: the metadata keys `bridge_unit`, `converter` and
/// `excitation_v` (recording-format.md), each overridden by `cli` where given. Throws
/// RecordingError naming the file when the declaration is incomplete or contradictory.
[[nodiscard]] InputUnit ResolveInputUnit(const Recording& rec, const UnitOverrides& cli = {});
/// One line saying what the unit is and where it came from.
[[nodiscard]] std::string Describe(const InputUnit& u);

/// Lowest and highest raw code of a converter, and the code of zero input.
[[nodiscard]] std::int64_t MinCode(const Converter& c);
[[nodiscard]] std::int64_t MaxCode(const Converter& c);
[[nodiscard]] std::int64_t ZeroCode(const Converter& c);
/// Bridge input per count (code step), mV/V; 0 when the description does not fix it (a
/// non-ratiometric converter without the excitation, or no reference at all).
[[nodiscard]] double MvvPerCount(const Converter& c, double excitation_v);

/// An inclusive range of column values, in the column's unit.
struct ValueRange {
  double min = 0.0;
  double max = 0.0;
  std::string unit;
  std::string what;  ///< what the range is, e.g. "codes of the 10-bit unsigned converter"
};

/// Refuses (RecordingError "FILE:LINE:COLUMN: …") the first b0 … b{channels−1} value outside
/// `range` (beyond half a step `tolerance`), naming the value, the range and the hint to declare
/// the unit.
void CheckBridgeRange(const Recording& rec, std::size_t channels, const ValueRange& range,
                      double tolerance);

/// Character column (1-based) of field `field` on file line `line` of `rec` (re-reads the file);
/// field + 1 when the file cannot be read.
[[nodiscard]] std::size_t FieldColumn(const Recording& rec, std::size_t line, std::size_t field);

/// Converts b0 … b{channels−1} of `rec` in place from `from` to mV/V. Counts are taken relative
/// to the converter's zero code. Throws RecordingError when the scale is not known.
void ConvertBridgesToMvv(Recording* rec, std::size_t channels, const InputUnit& from);
/// Converts raw codes in place to signed counts (code − zero code). Requires kCounts.
void ConvertCodesToCounts(Recording* rec, std::size_t channels, const InputUnit& from);

}  // namespace ftstack
