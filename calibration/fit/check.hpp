// Calibration check in place: a known tool weighed in a few robot poses against what the
// calibration reads, giving per-axis gain and cross-talk errors with uncertainties and a verdict.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "calibration/file/cal_file.hpp"
#include "measurement/recording.hpp"

namespace ftstack::cal {

/// One static pose: gravity in the sensor frame (from the robot) and the calibrated reading.
struct CheckPose {
  Eigen::Vector3d gravity_mps2 = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 1> reading = Eigen::Matrix<double, 6, 1>::Zero();  ///< N, N·m
};

/// The known tool: the reading of a static sensor is F = m·g, M = c × (m·g), plus a bias.
struct CheckTool {
  double mass_kg = 0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  /// Standard uncertainties of what is stated (0: exact): the tool's mass and each coordinate of
  /// its centre of mass, and the robot's orientation of each pose (rad, about each axis).
  double mass_sigma_kg = 0;
  double com_sigma_m = 0;
  double pose_angle_sigma_rad = 0;
};

/// Result for one axis.
struct AxisCheck {
  bool gain_excited = false;  ///< the tool loads this axis (|expected| ≥ 1 % of the tool's load)
  double gain_error = 0;      ///< relative gain error (reading / expected − 1) along the load
  double gain_sigma = 0;      ///< its standard uncertainty
  /// Reading that follows gravity in directions the axis should not see, at |g|: N or N·m.
  double crosstalk = 0;
  double crosstalk_sigma = 0;
  /// Largest error this tool shows on the axis over all gravity directions (gain and cross-talk
  /// together, bias removed), N or N·m, and its standard uncertainty.
  double worst_error = 0;
  double worst_sigma = 0;
  double residual_rms = 0;  ///< what the linear-in-gravity model leaves, N or N·m
  double allowed = 0;       ///< the limit: 2 × the calibration's stated uncertainty
  bool pass = true;
};

/// Result of a check.
struct CheckResult {
  std::array<AxisCheck, 6> axes{};
  Eigen::Matrix<double, 6, 1> bias = Eigen::Matrix<double, 6, 1>::Zero();  ///< fitted zero
  /// Rotation of the sensor frame seen in the force readings (the antisymmetric part of the
  /// force response), rad, about x, y, z, and its standard uncertainty.
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_sigma_rad = Eigen::Vector3d::Zero();
  /// Per axis: the rotation about it is resolved (beyond 4 σ); only those are named as an axis.
  std::array<bool, 3> rotation_resolved{};
  std::size_t residual_dof = 0;  ///< poses − 4: the degrees of freedom the scatter is read with
  double gravity_condition = 0;  ///< condition number of [1, g] over the poses
  std::size_t poses = 0;
  bool pass = true;
  std::string verdict;  ///< one line: "PASS: …" or "FAIL: …"
};

/// Fits reading = bias + K·g over the poses (least squares; needs ≥ 6 poses whose gravity
/// directions span three dimensions) and compares K with the tool's K₀ = [m·I; m·[c]×].
/// Every σ is honest with few poses: the scatter per axis is the larger of the residuals' and
/// what the pose angles' uncertainty predicts; read from the residuals with ν = poses − 4 degrees
/// of freedom it is widened by t_ν(99 %)/z(99 %) (Student's t; ×3.9 at 6 poses, ×1.8 at 8), so
/// that 3 σ covers what a known σ would; the tool's mass and centre-of-mass uncertainties add
/// in quadrature (they are systematic: no number of poses averages them out). An axis
/// fails when its worst error minus 3 σ exceeds `allowed` (2 × stated_uncertainty), or when its
/// residual RMS exceeds a non-zero `allowed` (the reading does not follow gravity linearly).
/// Throws std::invalid_argument for too few poses, gravity directions that do not span three
/// dimensions, a non-positive mass or non-finite input.
[[nodiscard]] CheckResult CheckCalibration(const std::vector<CheckPose>& poses,
                                           const CheckTool& tool,
                                           const std::array<double, 6>& stated_uncertainty);

/// The poses of a check recording (gx_mps2 gy_mps2 gz_mps2 and b* columns, already in the
/// calibration's input unit): the calibration is applied through the fixed-point core, and rows
/// with equal `pose` values (or each row, without that column) are averaged into one pose.
/// Throws RecordingError naming the file for a missing column, a row the core flags (status ≠ 0)
/// or a pose whose gravity varies by more than 0.05 m/s².
[[nodiscard]] std::vector<CheckPose> CheckPosesFromRecording(const CalFile& cal,
                                                             const Recording& rec);

/// Multi-line report: per-axis gain and cross-talk with uncertainties, the frame rotation, the
/// verdict last.
[[nodiscard]] std::string CheckSummary(const CheckResult& r, const CheckTool& tool);

}  // namespace ftstack::cal
