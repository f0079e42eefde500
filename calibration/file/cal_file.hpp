// Calibration files: versioned JSON with CRC-32, refused whole when corrupt; atomic replacement.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "firmware/fixed_calibration.hpp"
#include "hal/adc.hpp"

namespace ftstack::cal {

/// A calibration file that cannot be used. what() names the file (and line:column for syntax).
class CalFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// File schema identifier written by this version. Version 2 adds second-order terms
/// ("model"), temperature compensation ("temperature") and the feature list of the fixed-point
/// form; version 1 files (affine only) are still read.
inline constexpr const char* kCalSchema = "ftstack-cal/2";
/// The older schema still accepted.
inline constexpr const char* kCalSchemaV1 = "ftstack-cal/1";
/// Written instead of kCalSchema when the file flags axes invalid ("invalid_axes": a rig that
/// never excited them): a reader older than the field refuses the file rather than serve them.
inline constexpr const char* kCalSchemaV3 = "ftstack-cal/3";

/// Names of the six axes in files and messages: Fx Fy Fz Mx My Mz.
inline constexpr const char* kAxisNames[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
/// "Mz" or "Mx, Mz" for a bit set of axes.
[[nodiscard]] std::string AxisList(std::uint8_t axes);

/// The contents of a calibration file.
struct CalFile {
  std::string serial = "unknown";
  std::string date;                 ///< ISO 8601 date of the calibration
  std::string source = "fit";       ///< "fit", "ideal" (from the sensor model), "ati"
  std::string input_unit = "mV/V";  ///< unit of the bridge columns the matrix expects
  fw::FloatCalibration cal{};       ///< matrix (N, N·m per input unit), offsets, bias
  /// ADC the fixed-point form is made for: rails and full scale (input unit at max_counts).
  hal::AdcInfo adc{};
  std::array<double, 6> rated{};  ///< rated range per axis, N and N·m
  /// Per-axis standard uncertainty of a calibrated reading (for a fit: the held-out RMS error
  /// over whole load blocks), N and N·m.
  std::array<double, 6> uncertainty{};
  nlohmann::json extra = nlohmann::json::object();  ///< fields of later issues, kept verbatim
};

/// CRC-32 (IEEE 802.3, reflected, as zlib) of a byte string.
[[nodiscard]] std::uint32_t Crc32(const std::string& bytes);

/// Serialises to JSON including the fixed-point form (recomputed) and the CRC field.
/// Throws CalFileError if the calibration is refused by the fixed-point loader.
[[nodiscard]] nlohmann::json ToJson(const CalFile& file);
/// Parses and checks JSON (schema, CRC, shapes, finiteness, loader acceptance).
[[nodiscard]] CalFile FromJson(const nlohmann::json& j, const std::string& path);
/// The CRC-32 stored in / computed for a calibration JSON (over the compact dump without "crc32").
[[nodiscard]] std::uint32_t ContentCrc(const nlohmann::json& j);

/// Reads and verifies a calibration file. Throws CalFileError naming the file and, for syntax
/// errors, line and column.
[[nodiscard]] CalFile LoadCalFile(const std::string& path);
/// The same for a file's text already in memory; `path` only names it in messages.
[[nodiscard]] CalFile ParseCalFile(const std::string& text, const std::string& path);
/// Parses JSON text; throws CalFileError naming `path` and, for syntax errors, line:column.
[[nodiscard]] nlohmann::json ParseJsonText(const std::string& text, const std::string& path);
/// Writes atomically: temporary file, fsync, rename over `path`, fsync of the directory.
void SaveCalFile(const std::string& path, const CalFile& file);
/// The same for any text. With a `crash_tag` T the steps are crash-injection points (see
/// CrashPoint): "T-write" (the temporary file torn: half written), "T-fsync", "T-rename" and
/// "T-dirsync" (each just before that step).
void WriteFileAtomic(const std::string& path, const std::string& text,
                     const char* crash_tag = nullptr);

/// Test hook for crash injection: when the environment variable FTSTACK_CRASH_AT equals `step`,
/// the process kills itself here with SIGKILL (no handler, no flush, no unwinding — as a power
/// cut would stop it, minus the kernel's page cache). Does nothing otherwise. Used by
/// `ftcal install` (CalSlots::Install) and its crash test; never set it in production.
void CrashPoint(const std::string& step);

/// The default ADC of the simulated sensor: 24-bit, ±3.90625 mV/V (gain 128, ratio 0.5).
[[nodiscard]] hal::AdcInfo DefaultAdc(std::uint8_t channels);

/// The ADC description a device uses for `file`: the device's own for a calibration in mV/V; for
/// one in raw counts, the file's scale with the device's rate, provided the device's rails are the
/// file's converter's (else CalFileError naming both).
[[nodiscard]] hal::AdcInfo AdcForDevice(const CalFile& file, const hal::AdcInfo& device);

/// Converts to the firmware's integer form for `adc`; throws CalFileError on refusal.
[[nodiscard]] fw::FixedCalibration ToFixed(const CalFile& file, const hal::AdcInfo& adc,
                                           fw::LoadReport* report = nullptr);

}  // namespace ftstack::cal
