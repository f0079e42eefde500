// ftcal check's uncertainties against the truth over many seeded cases with few poses: a
// generator written here (not the fit's) draws the true tool, the robot's pose errors, the
// sensor's true gain error or frame rotation and the reading noise; the check sees only the
// stated tool, the robot's gravity and the readings. Its 1 σ must cover the true gain error in
// ≥ 60 % of cases and 3 σ in ≥ 97 %, and a rotation axis it names must be a true one.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "calibration/fit/check.hpp"

namespace {

using ftstack::cal::CheckCalibration;
using ftstack::cal::CheckPose;
using ftstack::cal::CheckResult;
using ftstack::cal::CheckTool;
using Vec6 = Eigen::Matrix<double, 6, 1>;

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kG = 9.80665;

struct Coverage {
  int cases = 0, within1 = 0, within3 = 0, false_axes = 0, rotations = 0, named = 0;
};

Eigen::Matrix3d SmallRotation(const Eigen::Vector3d& w) {
  return w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                      : Eigen::Matrix3d::Identity();
}

/// One case: `poses` random orientations; a 1 % gain error on one axis or a 0.5° rotation of
/// the sensor frame about one axis (alternating with `k`).
void RunCase(int poses, int k, std::mt19937_64& rng, Coverage* cov) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double mass = 1.0 + 4.0 * uni(rng);
  const Eigen::Vector3d com(0.02 * gauss(rng), 0.02 * gauss(rng), 0.03 + 0.07 * uni(rng));
  CheckTool stated;
  stated.mass_sigma_kg = 0.005 * mass;
  stated.com_sigma_m = 0.001;
  stated.pose_angle_sigma_rad = 0.02 * kDeg;
  stated.mass_kg = mass + stated.mass_sigma_kg * gauss(rng);
  stated.com_m = com + stated.com_sigma_m * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
  Eigen::Matrix<double, 6, 6> t = Eigen::Matrix<double, 6, 6>::Identity();
  std::array<double, 6> true_gain{};
  Eigen::Vector3d true_rot = Eigen::Vector3d::Zero();
  const double sign = uni(rng) < 0.5 ? -1.0 : 1.0;
  if (k % 2 == 0) {
    const int axis = static_cast<int>(uni(rng) * 6) % 6;
    true_gain[static_cast<std::size_t>(axis)] = 0.01 * sign;
    t(axis, axis) += 0.01 * sign;
  } else {
    true_rot(static_cast<int>(uni(rng) * 3) % 3) = 0.5 * kDeg * sign;
    t.topLeftCorner<3, 3>() = SmallRotation(true_rot);
    t.bottomRightCorner<3, 3>() = SmallRotation(true_rot);
  }
  Vec6 bias;
  for (int a = 0; a < 6; ++a) bias(a) = (a < 3 ? 0.3 : 0.01) * gauss(rng);
  std::vector<CheckPose> ps;
  for (int p = 0; p < poses; ++p) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Vector3d g_true = q.toRotationMatrix().transpose() * Eigen::Vector3d(0, 0, -kG);
    const Eigen::Vector3d tilt =
        stated.pose_angle_sigma_rad * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    CheckPose pose;
    pose.gravity_mps2 = SmallRotation(tilt) * g_true;  // what the robot reports
    Vec6 w;
    w.head<3>() = mass * g_true;
    w.tail<3>() = com.cross(mass * g_true);
    pose.reading = t * w + bias;
    for (int a = 0; a < 6; ++a) pose.reading(a) += (a < 3 ? 5e-3 : 3e-4) * gauss(rng);
    ps.push_back(pose);
  }
  const CheckResult r = CheckCalibration(ps, stated, {0.02, 0.02, 0.02, 0.002, 0.002, 0.002});
  for (std::size_t a = 0; a < 6; ++a) {
    if (!r.axes[a].gain_excited) continue;
    const double err = std::abs(r.axes[a].gain_error - true_gain[a]);
    ++cov->cases;
    cov->within1 += err <= r.axes[a].gain_sigma ? 1 : 0;
    cov->within3 += err <= 3.0 * r.axes[a].gain_sigma ? 1 : 0;
  }
  for (int i = 0; i < 3; ++i) {
    const bool wrong = true_rot(i) == 0.0 || (r.rotation_rad(i) > 0) != (true_rot(i) > 0);
    if (r.rotation_resolved[static_cast<std::size_t>(i)] && wrong) ++cov->false_axes;
    if (true_rot(i) != 0.0) {
      ++cov->rotations;
      cov->named += r.rotation_resolved[static_cast<std::size_t>(i)] && !wrong ? 1 : 0;
    }
  }
}

TEST(CheckCoverage, SigmaCoversTheTruthWithFewPoses) {
  for (const int poses : {6, 8, 12}) {
    std::mt19937_64 rng(4242 + static_cast<unsigned>(poses));
    Coverage c;
    for (int k = 0; k < 400; ++k) RunCase(poses, k, rng, &c);
    const double p1 = 100.0 * c.within1 / c.cases;
    const double p3 = 100.0 * c.within3 / c.cases;
    std::printf(
        "%2d poses: %d axis cases, 1 sigma covers %.1f %%, 3 sigma %.1f %%, %d false "
        "rotation axes, %d of %d true rotations named\n",
        poses, c.cases, p1, p3, c.false_axes, c.named, c.rotations);
    EXPECT_GE(p1, 60.0) << poses;
    EXPECT_GE(p3, 97.0) << poses;
    EXPECT_EQ(c.false_axes, 0) << poses;
  }
}

}  // namespace
