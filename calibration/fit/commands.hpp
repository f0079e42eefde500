// ftcal's subcommands as library calls (fit, check, verify, import-ati): inputs in, files and
// the text a user reads out, so tests reach them without the command line.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/ati.hpp"
#include "calibration/fit/check.hpp"
#include "calibration/fit/fit.hpp"
#include "firmware/fixed_calibration.hpp"
#include "measurement/recording.hpp"
#include "measurement/units.hpp"

namespace ftstack::cal {

/// What `ftcal fit` is told (docs/spec/cli.md).
struct FitRequest {
  std::string in_path;
  std::string model_name = "auto";  ///< "auto" or a ModelKind name
  int folds = 10;
  bool by_group = true;  ///< hold out load directions (groups), else load blocks
  bool allow_unexcited = false;
  bool identify_jig = false;  ///< known-mass recordings: identify the loading jig
  std::string serial = "unknown";
  std::string date;
  std::optional<std::array<double, 6>> rated;  ///< --rated, else the sensor's
  std::optional<hal::AdcInfo> adc;             ///< the sensor's converter, if one was given
  UnitOverrides units;                         ///< --bridge-unit, --converter, --excitation-v
};

/// What a fit produced: the file to write, the fit, its data and what the user is told.
struct FitOutcome {
  CalFile file;
  FitResult result;
  RigData data;
  fw::LoadReport fixed{};
  std::string text;  ///< unit line, summary, warnings
};

/// Reads the rig recording (a reference wrench, or known masses turned into one, with the jig's
/// load added when asked), checks every axis's excitation, fits and builds the calibration file.
/// Throws (std::invalid_argument, RecordingError, CalFileError) with one line naming the file.
[[nodiscard]] FitOutcome FitFromRecording(const FitRequest& request);

/// `ftcal apply` on files: the recording converted into the calibration's input unit, run
/// through the fixed-point core and written. `log` holds the lines for stderr (invalid axes, the
/// unit used, rows written); `status` the output's status column.
struct ApplyOutcome {
  std::string log;
  std::vector<double> status;
};
[[nodiscard]] ApplyOutcome ApplyToFile(const std::string& cal_path, const std::string& in_path,
                                       const std::string& out_path, const UnitOverrides& units);

/// `ftcal payload`: identifies the payload from static readings, writes the file dated `date`
/// and returns the summary.
[[nodiscard]] std::string PayloadToFile(const std::string& in_path, const std::string& out_path,
                                        double max_condition, const std::string& date);

/// `ftcal active`: one line on the active slot; *warning gets a note (e.g. the other slot bad).
[[nodiscard]] std::string ActiveSlotLine(const std::string& slots_dir, std::string* warning);

/// `ftcal verify`: integrity and the fixed-point form. Sets *incomplete when the file flags an
/// axis invalid. Throws CalFileError for a corrupt file.
[[nodiscard]] std::string VerifyCalFile(const std::string& path, bool* incomplete);

/// `ftcal import-ati`'s report of an import (matrix, rated range, fixed-point error).
[[nodiscard]] std::string AtiImportSummary(const std::string& ati_path, const AtiImport& imp);

/// The worst-case fixed-point error line.
[[nodiscard]] std::string WorstCaseLine(const fw::LoadReport& rep);

/// What `ftcal check` is told: a calibration, a recording of static poses, and the tool (a
/// payload file, or mass and centre of mass).
struct CheckRequest {
  std::string cal_path;
  std::string in_path;
  std::string payload_path;
  std::optional<double> mass_kg;
  std::optional<std::array<double, 3>> com_m;
  /// Standard uncertainties of the tool's mass (kg), of each coordinate of its centre of mass
  /// (m) and of each pose's orientation from the robot (rad); 0: exact.
  double mass_sigma_kg = 0.0;
  double com_sigma_m = 0.0;
  double pose_angle_sigma_rad = 0.0;
  UnitOverrides units;
};

/// Runs the check: reads the calibration and the recording (converted into the calibration's
/// input unit), takes the tool from the payload file or the given mass and centre of mass and
/// compares. Throws with one line for bad input.
[[nodiscard]] CheckResult RunCheck(const CheckRequest& request, std::string* text);

}  // namespace ftstack::cal
