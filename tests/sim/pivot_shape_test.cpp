// Tests of the similarity registration of measured strip shapes onto the pivot model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "sim/pivot/pivot.hpp"
#include "sim/pivot/shape_registration.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim::pivot {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::vector<Eigen::Vector2d> ModelStrip(double theta_deg, double v, double h, int strip = 0) {
  PivotOptions o;
  o.want_shape = true;
  const PivotResult r =
      SolvePivot(PivotGeometry{}, {theta_deg * kDeg, v, h}, PivotMethod::kExact, o);
  EXPECT_TRUE(r.valid) << r.reason;
  return r.shape_m[strip];
}

// Points of a polyline at arc-length fractions `f` (any order).
std::vector<Eigen::Vector2d> Sample(const std::vector<Eigen::Vector2d>& poly,
                                    const std::vector<double>& f) {
  std::vector<double> s(poly.size(), 0.0);
  for (size_t k = 1; k < poly.size(); ++k) s[k] = s[k - 1] + (poly[k] - poly[k - 1]).norm();
  std::vector<Eigen::Vector2d> out;
  for (double fi : f) {
    const double target = fi * s.back();
    const size_t k = std::min<size_t>(
        poly.size() - 1,
        std::max<size_t>(
            1, static_cast<size_t>(std::lower_bound(s.begin(), s.end(), target) - s.begin())));
    const double u = (target - s[k - 1]) / (s[k] - s[k - 1]);
    out.push_back(poly[k - 1] + u * (poly[k] - poly[k - 1]));
  }
  return out;
}

TEST(PivotShape, FitSimilarityRecoversAnExactTransform) {
  std::vector<Eigen::Vector2d> from = {{0, 0}, {1, 0}, {1, 2}, {-0.5, 0.7}};
  for (const bool mirror : {false, true}) {
    Similarity2 t;
    t.scale = 3.5;
    const double a = 0.8;
    t.rotation << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    if (mirror) t.rotation = t.rotation * Eigen::Vector2d(1, -1).asDiagonal();
    t.translation = {10, -4};
    std::vector<Eigen::Vector2d> to;
    for (const auto& p : from) to.push_back(t.Apply(p));
    const Similarity2 fit = FitSimilarity(from, to, true);
    EXPECT_NEAR(fit.scale, 3.5, 1e-12);
    EXPECT_EQ(fit.reflected, mirror);
    EXPECT_LT((fit.rotation - t.rotation).norm(), 1e-12);
    EXPECT_LT((fit.translation - t.translation).norm(), 1e-10);
    // Without reflection allowed a mirrored set cannot be matched exactly.
    if (mirror) {
      EXPECT_FALSE(FitSimilarity(from, to, false).reflected);
    }
  }
}

// The camera experiment: the model strip photographed at 5000 px/m, rotated, mirrored (image y
// axis down), shifted, with 0.4 px edge noise, points shuffled and unevenly spaced.
TEST(PivotShape, RegistrationRecoversKnownSimilarityAndNoiseLevel) {
  const auto model = ModelStrip(15.0, 5.0, 3.0);
  for (const unsigned seed : {42u, 7u, 2024u, 99u, 5u}) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 0.4);
    std::vector<double> f = {0.0, 1.0};
    for (int k = 0; k < 398; ++k) f.push_back(uni(rng));
    std::shuffle(f.begin(), f.end(), rng);
    const std::vector<Eigen::Vector2d> truth = Sample(model, f);

    const double px_per_m = 5000.0, angle = 123 * kDeg;
    Eigen::Matrix2d rot;
    rot << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    const Eigen::Matrix2d flip = Eigen::Vector2d(1, -1).asDiagonal();
    const Eigen::Vector2d shift(640, 480);
    std::vector<Eigen::Vector2d> pixels;
    for (const auto& p : truth) {
      pixels.push_back(flip * (px_per_m * (rot * p)) + shift +
                       Eigen::Vector2d(noise(rng), noise(rng)));
    }
    const ShapeRegistration reg = RegisterShape(model, pixels);
    // Model-to-pixel map is flip·s·R; the registration is its inverse: scale 1/s, a reflection.
    EXPECT_TRUE(reg.measured_to_model.reflected);
    // Scale: set mainly by the two end points, noise 0.4 px per coordinate over a ~490 px strip:
    // standard deviation ≈ 0.4·√2/490 ≈ 0.12 %; allow 4 sigma.
    EXPECT_NEAR(reg.measured_to_model.scale * px_per_m, 1.0, 5e-3);
    const Eigen::Matrix2d expected_r = (flip * rot).transpose();
    EXPECT_LT((reg.measured_to_model.rotation - expected_r).norm(), 5e-3);
    // Residual: only the noise component normal to the curve remains, RMS 0.4 px / s; the RMS of
    // 400 samples scatters by ≈ 1/√(2·400) = 3.5 %.
    const double expected_rms = 0.4 / px_per_m;
    EXPECT_NEAR(reg.rms_residual_m / expected_rms, 1.0, 0.15);
    EXPECT_EQ(reg.residuals_m.size(), pixels.size());
  }
}

TEST(PivotShape, DifferentShapeLeavesALargeResidual) {
  // A strip bent to 15° under compression is not the shape of the strip at 15° under tension:
  // after the best similarity the residual is far above the 0.4 px noise level.
  const auto model = ModelStrip(15.0, 10.0, 0.0);
  const auto other = ModelStrip(15.0, -80.0, 0.0);
  std::vector<double> f;
  for (int k = 0; k <= 200; ++k) f.push_back(k / 200.0);
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : Sample(other, f)) pixels.push_back(4000.0 * p);
  const ShapeRegistration same = RegisterShape(model, [&] {
    std::vector<Eigen::Vector2d> px;
    for (const auto& p : Sample(model, f)) px.push_back(4000.0 * p);
    return px;
  }());
  const ShapeRegistration diff = RegisterShape(model, pixels);
  EXPECT_LT(same.rms_residual_m, 1e-7);
  EXPECT_GT(diff.rms_residual_m, 5 * 0.4 / 4000.0);
}

TEST(PivotShape, BadInputIsRejected) {
  const auto model = ModelStrip(5.0, 0.0, 0.0);
  EXPECT_THROW((void)RegisterShape(model, {{0, 0}, {1, 1}}), std::invalid_argument);
  EXPECT_THROW((void)RegisterShape(model, {{0, 0}, {1, 1}, {NAN, 2}}), std::invalid_argument);
  EXPECT_THROW((void)RegisterShape(model, {{1, 1}, {1, 1}, {1, 1}}), std::invalid_argument);
}

TEST(PivotShape, ReadPointsCsvAcceptsCommonLayoutsAndNamesTheFaultyPlace) {
  const std::string path = ftstack::test::ProcessTempDir() + "pivot_points.csv";
  {
    std::ofstream f(path);
    f << "# edge points\nx y\n1.5, 2\n3;4\r\n  5\t6\n\n";
  }
  const auto pts = ReadPointsCsv(path);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[0], Eigen::Vector2d(1.5, 2));
  EXPECT_EQ(pts[2], Eigen::Vector2d(5, 6));
  auto error_of = [&](const std::string& text) {
    {
      std::ofstream f(path);
      f << text;
    }
    try {
      (void)ReadPointsCsv(path);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of("1,2\n3,nan\n5,6\n"), path + ":2:3: 'nan' is not a finite number");
  EXPECT_EQ(error_of("1,2\n3,4,9\n5,6\n"), path + ":2:5: expected two numbers x,y");
  EXPECT_EQ(error_of("1,2\n3\n5,6\n"), path + ":2:2: expected two numbers x,y");
  EXPECT_EQ(error_of("1,2\n3,4\n"), path + ":3:1: need at least 3 points, got 2");
  EXPECT_NE(error_of("").find(":1:1: need at least 3 points"), std::string::npos);
  EXPECT_EQ(error_of("1,2\n"), path + ":2:1: need at least 3 points, got 1");
  EXPECT_THROW((void)ReadPointsCsv(path + ".missing"), std::invalid_argument);
}

}  // namespace
}  // namespace ftstack::sim::pivot
