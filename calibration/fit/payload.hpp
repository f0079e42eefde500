// Payload identification: mass, centre of mass and sensor bias from static readings in known poses.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration/file/payload_file.hpp"
#include "measurement/recording.hpp"

namespace ftstack::cal {

/// A reading set that cannot separate the parameters. what() says which parameter is not
/// identifiable and which poses to add.
class PayloadIdentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One static reading: gravity in the sensor frame (m/s², from the robot's pose) and the
/// measured wrench (Fx Fy Fz Mx My Mz, N and N·m).
struct PayloadReading {
  std::array<double, 3> gravity_mps2{};
  std::array<double, 6> wrench{};
};

struct PayloadFitOptions {
  /// Largest accepted condition number of each (column-scaled) design: the force block
  /// [g/|g| I] for (m·|g|, F_b) and the moment block [−[g]×/|g| I] for (m·c·|g|, M_b). 30 means
  /// gravity directions spread by roughly ≥ 5° in every direction that matters.
  double max_condition = 30.0;
};

/// The fit with its diagnostics (the file holds the values and 1 σ uncertainties).
struct PayloadFit {
  PayloadFile file;
  double force_condition = 0;              ///< condition number of the scaled force block
  double moment_condition = 0;             ///< condition number of the scaled moment block
  Eigen::Matrix4d force_cov;               ///< covariance of (m, F_b), from the force residuals
  Eigen::Matrix<double, 6, 6> moment_cov;  ///< covariance of (m·c, M_b), from the moment residuals
};

/// Least-squares fit of F = m·g + F_b and M = (m·c) × g + M_b (two independent linear blocks;
/// each block's covariance is its residual variance times (AᵀA)⁻¹; c = (m·c)/m with first-order
/// propagation). Throws PayloadIdentError for fewer than 3 readings, non-finite input or a
/// design above max_condition (naming the parameter and the poses to add).
[[nodiscard]] PayloadFit FitPayload(const std::vector<PayloadReading>& readings,
                                    const PayloadFitOptions& options = {});

/// Readings from a recording with columns gx_mps2 gy_mps2 gz_mps2 Fx Fy Fz Mx My Mz (one
/// static reading per row); throws RecordingError naming the file for a missing column.
[[nodiscard]] std::vector<PayloadReading> PayloadReadingsFromRecording(const Recording& rec);

/// A short human-readable summary of a fit (values ± 1 σ, residuals, conditioning).
[[nodiscard]] std::string PayloadSummary(const PayloadFit& fit);

}  // namespace ftstack::cal
