// Import of ATI DAQ F/T calibration files (.cal, versions 1.0 and 1.1) into our calibration form.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "calibration/file/cal_file.hpp"

namespace ftstack::cal {

/// What an ATI import produced.
struct AtiImport {
  CalFile file;                 ///< input unit V, matrix N and N·m per V, rated per axis
  std::string version;          ///< CalFileVersion attribute ("1.0", "1.1", …)
  bool used_user_axis = false;  ///< the matrix came from UserAxis rows (else Axis + transform)
  std::vector<std::string> warnings;  ///< disagreements and ignored content, one line each
  Eigen::MatrixXd from_axis;          ///< Axis/scale with BasicTransform, SI (empty if absent)
  Eigen::MatrixXd from_user_axis;     ///< UserAxis rows, SI (empty if absent)
};

/// Wrench transform of ATI's BasicTransform / tool transform: the wrench seen at a point moved
/// by d (m) in a frame rotated by rx, ry, rz (degrees; rotation Rx·Ry·Rz of the new frame):
/// F' = Rᵀ·F, M' = Rᵀ·(M − d × F) with R = Rx(rx)·Ry(ry)·Rz(rz).
[[nodiscard]] Eigen::Matrix<double, 6, 6> AtiWrenchTransform(const Eigen::Vector3d& d_m,
                                                             double rx_deg, double ry_deg,
                                                             double rz_deg);

/// Unit factors: N per force unit, N·m per torque unit, m per distance unit, degrees per angle
/// unit (the names ATI's files use). 0 for an unknown name.
[[nodiscard]] double AtiForceToN(const std::string& unit);
[[nodiscard]] double AtiTorqueToNm(const std::string& unit);
[[nodiscard]] double AtiDistanceToM(const std::string& unit);
[[nodiscard]] double AtiAngleToDeg(const std::string& unit);

/// Parses an ATI DAQ calibration file. Version 1.0: Axis rows divided by their scale, units
/// converted, BasicTransform applied as ATI's DAQ F/T library does. Version 1.1: UserAxis rows
/// (already scaled and transformed); when both kinds are present they are compared and a
/// warning names the rows that disagree beyond the 5-decimal rounding of the file. Throws
/// CalFileError "FILE:LINE:COLUMN: reason" for malformed content.
[[nodiscard]] AtiImport ParseAtiCal(const std::string& text, const std::string& path);
/// Reads and parses a file.
[[nodiscard]] AtiImport ImportAtiCal(const std::string& path);

}  // namespace ftstack::cal
