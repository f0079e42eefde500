// Whether a rig recording excites each axis enough to calibrate it: load range against the rated
// range and the part of each axis's load that the other axes do not explain (rank, conditioning).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <string>

namespace ftstack::cal {

struct ExcitationOptions {
  /// The load on an axis must sweep at least this fraction of its rated range (max − min).
  double min_range_fraction = 0.2;
  /// The RMS of the part of an axis's load (÷ rated) that an affine combination of the other
  /// axes cannot reproduce must reach this: an axis loaded only in proportion to another cannot
  /// be told apart from it (the load set's rank lacks it).
  double min_independent_fraction = 0.02;
};

/// What the recording shows for one axis.
struct AxisExcitation {
  double range_fraction = 0.0;        ///< (max − min) of the reference load ÷ rated
  double independent_fraction = 0.0;  ///< RMS of the part the other axes do not explain ÷ rated
  bool excited = false;
};

struct ExcitationReport {
  std::array<AxisExcitation, 6> axes{};
  std::uint8_t unexcited = 0;  ///< bit per axis that fails a criterion
  double condition = 0.0;      ///< condition number of [1, wrench ./ rated] (LoadSetCondition)
  /// One line naming every unexcited axis and the figures that fail ("" when all are excited).
  std::string Refusal(const std::array<double, 6>& rated, const ExcitationOptions& options) const;
};

/// Checks every axis of `wrench` (rows × 6, N and N·m) against `rated` (> 0 per axis). Throws
/// std::invalid_argument for fewer than 2 rows or a rated range that is not positive.
[[nodiscard]] ExcitationReport CheckExcitation(const Eigen::MatrixXd& wrench,
                                               const std::array<double, 6>& rated,
                                               const ExcitationOptions& options = {});

}  // namespace ftstack::cal
