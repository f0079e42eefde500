// Similarity registration of measured strip edge points (pixels, any frame) onto a model centre
// line.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace ftstack::sim::pivot {

/// x ↦ scale·R·x + t. R is a rotation, or a reflection (det −1) when `reflected`.
struct Similarity2 {
  double scale = 1.0;
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  bool reflected = false;
  [[nodiscard]] Eigen::Vector2d Apply(const Eigen::Vector2d& x) const {
    return scale * (rotation * x) + translation;
  }
  /// Rotation angle of R (for a reflection: of R·diag(1, −1)), rad.
  [[nodiscard]] double AngleRad() const;
};

/// Weighted least-squares similarity mapping `from[k]` onto `to[k]` (Umeyama 1991; in 2-D its SVD
/// has a closed form). `weights` empty = all 1. Throws std::invalid_argument if the sizes differ,
/// fewer than 2 points, negative weights, or `from` is degenerate.
[[nodiscard]] Similarity2 FitSimilarity(const std::vector<Eigen::Vector2d>& from,
                                        const std::vector<Eigen::Vector2d>& to,
                                        bool allow_reflection,
                                        const std::vector<double>& weights = {});

struct ShapeRegistration {
  Similarity2 measured_to_model;  ///< Maps measured points (pixels) into the model frame (m).
  double rms_residual_m = 0.0;    ///< RMS distance of the registered points to the model curve.
  double max_residual_m = 0.0;
  std::vector<double> residuals_m;  ///< Per measured point, in the caller's order.
  int iterations = 0;
};

/// Registers edge points of one bent strip, measured from end to end in any order and any frame
/// (image pixels, y down allowed), onto the model's centre line `model_m` (ordered polyline, m).
/// Method: order the points along their principal axis; initial correspondences by arc-length
/// fraction (invariant under a similarity); then alternate closest points on the model curve
/// (the two extreme points stay pinned to the curve's ends, which fixes the scale along the strip)
/// with the closed-form similarity, trying both end-to-end directions and keeping the better fit.
/// `allow_reflection` accepts mirror-image frames (a camera's y-down pixel axes).
/// Throws std::invalid_argument for fewer than 3 points, non-finite values or degenerate input.
[[nodiscard]] ShapeRegistration RegisterShape(const std::vector<Eigen::Vector2d>& model_m,
                                              const std::vector<Eigen::Vector2d>& measured_px,
                                              bool allow_reflection = true);

/// Reads measured points, one "x,y" per line (comma, semicolon, tab or spaces between; '#' starts a
/// comment line; an optional non-numeric header on the first line). Throws std::invalid_argument
/// "FILE:LINE:COLUMN: reason" for anything else, non-finite numbers, or fewer than 3 points.
[[nodiscard]] std::vector<Eigen::Vector2d> ReadPointsCsv(const std::string& path);

}  // namespace ftstack::sim::pivot
