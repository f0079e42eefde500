// Hub-and-spoke body against textbook closed forms: spoke torque sensor, floating beams, rim
// springs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/beam_element.hpp"
#include "sim/flexure_body.hpp"

namespace ftstack::sim {
namespace {

constexpr double kE = 200e9;
constexpr double kNu = 0.3;

// Spoke body: 25 mm spokes, 5 mm wide (tangential) × 3 mm high, steel.
FlexureGeometry Spokes(int beams) {
  return FlexureGeometry{.beam_count = beams,
                         .hub_radius_m = 0.012,
                         .rim_radius_m = 0.037,
                         .beam_width_m = 0.005,
                         .beam_height_m = 0.003,
                         .e_pa = kE,
                         .poisson = kNu};
}

Wrench Axis(int k, double value) {
  Wrench w = Wrench::Zero();
  w(k) = value;
  return w;
}

class FlexureSpokes : public ::testing::TestWithParam<int> {};

// Spoke torque sensor. A hub rotation θ moves each spoke's hub end tangentially by r·θ and turns it
// by θ, the rim end clamped. The end-stiffness coefficients of a clamped beam (Przemieniecki,
// Theory of Matrix Structural Analysis, §5) give the hub end force F = EI/L³·(12 r + 6 L)·θ and
// moment M₀ = EI/L³·(6 L r + 4 L²)·θ, hence the torque stiffness
// k_θ = n·(r·F + M₀)/θ = n·4·E·I·(3 r² + 3 r L + L²)/L³ and the in-plane bending moment
// M(s) = M₀ − F·s along the spoke; the side faces carry ε = M·(w/2)/(E·I).
TEST_P(FlexureSpokes, MzFollowsTheSpokeTorqueSensorClosedForm) {
  const int n = GetParam();
  const FlexureBody body(Spokes(n));
  const double r = body.geometry().hub_radius_m;
  const double l = body.beam_length_m();
  const double w = body.geometry().beam_width_m;
  const double ei = kE * body.section().iz_m4;
  const double k_theta = n * 4 * ei * (3 * r * r + 3 * r * l + l * l) / (l * l * l);
  const double mz = 7.5;
  const auto d = body.HubDisplacement(Axis(5, mz));
  EXPECT_NEAR(d(5), mz / k_theta, 1e-9 * std::abs(d(5)));
  EXPECT_NEAR(body.Stiffness()(5, 5), k_theta, 1e-9 * k_theta);
  const double theta = mz / k_theta;
  const double f = ei / (l * l * l) * (12 * r + 6 * l) * theta;
  const double m0 = ei / (l * l * l) * (6 * l * r + 4 * l * l) * theta;
  for (int i = 0; i < n; ++i) {
    for (double frac : {0.0, 0.15, 0.5, 0.85, 1.0}) {
      const double s = frac * l;
      const double expect = (m0 - f * s) * (w / 2) / ei;
      const GaugeStrain plus = body.StrainAt({i, s, BeamFace::kPlusY, 0.0, 0.0}, Axis(5, mz));
      const GaugeStrain minus = body.StrainAt({i, s, BeamFace::kMinusY, 0.0, 0.0}, Axis(5, mz));
      const double tol = 1e-9 * std::abs(m0 * w / ei);
      // Sign convention of the faces aside, the two sides are equal and opposite.
      EXPECT_NEAR(std::abs(plus.axial), std::abs(expect), tol) << "beam " << i << " s " << s;
      EXPECT_NEAR(plus.axial, -minus.axial, tol);
      EXPECT_NEAR(plus.transverse, -kNu * plus.axial, tol);
      // No out-of-plane bending or axial load under a pure Mz.
      EXPECT_NEAR(body.StrainAt({i, s, BeamFace::kTop, 0.0, 0.0}, Axis(5, mz)).axial, 0.0, tol);
    }
  }
  // The strain reverses between the roots: |M(L)|/|M(0)| = (6 r + 2 L)/(6 r + 4 L).
  const double e_hub = body.StrainAt({0, 0.0, BeamFace::kPlusY, 0.0, 0.0}, Axis(5, mz)).axial;
  const double e_rim = body.StrainAt({0, l, BeamFace::kPlusY, 0.0, 0.0}, Axis(5, mz)).axial;
  EXPECT_NEAR(e_rim / e_hub, -(6 * r + 2 * l) / (6 * r + 4 * l), 1e-9);
}

// Floating beams: a radial release at every rim end (compliance ≫ the beam's L/EA) removes the
// axial path, so a lateral force Fx is carried only by tangential bending of the spokes as guided
// beams (the hub does not turn: Σ sin θᵢ = 0). Each spoke takes Fₜ = 2·Fx·|sin θᵢ|/n, the hub
// stiffness is (n/2)·12·E·I_z/L³ and the side strain M·(w/2)/(E·I_z) with M = Fₜ·(L/2 − s).
// With a rigid rim the same force also meets the axial stiffness: K_xx = (n/2)(12 E I_z/L³ + EA/L).
TEST_P(FlexureSpokes, FloatingBeamsCarryALateralForceByTangentialBendingOnly) {
  const int n = GetParam();
  FlexureGeometry g = Spokes(n);
  const FlexureBody rigid(g);
  const double l = rigid.beam_length_m();
  const double w = g.beam_width_m;
  const double ei = kE * rigid.section().iz_m4;
  const double k_t = 12 * ei / (l * l * l);
  const double k_a = kE * rigid.section().area_m2 / l;
  EXPECT_NEAR(rigid.Stiffness()(0, 0), n / 2.0 * (k_t + k_a), 1e-9 * n * k_a);

  g.rim_compliance = {1e-2, 0, 0, 0, 0, 0};  // 1e-2 m/N against L/EA ≈ 1e-8 m/N
  const FlexureBody floating(g);
  const double release = 1e-4;  // relative effect of the finite release spring, ≈ 1/(c·k_t)
  EXPECT_NEAR(floating.Stiffness()(0, 0), n / 2.0 * k_t, release * n * k_t);
  const double fx = 120.0;
  EXPECT_NEAR(floating.HubDisplacement(Axis(0, fx))(0), fx / (n / 2.0 * k_t), release * fx / k_t);
  for (int i = 0; i < n; ++i) {
    const double th = 2 * std::numbers::pi * i / n;
    const double ft = 2 * fx * std::abs(std::sin(th)) / n;
    const auto ends = floating.BeamEndForces(i, Axis(0, fx));
    EXPECT_NEAR(ends(0), 0.0, release * fx) << "axial force, beam " << i;
    EXPECT_NEAR(std::abs(ends(1)), ft, release * fx) << "tangential force, beam " << i;
    for (double frac : {0.0, 0.2, 0.8}) {
      const double s = frac * l;
      const double expect = ft * (l / 2 - s) * (w / 2) / ei;
      const double got = floating.StrainAt({i, s, BeamFace::kPlusY, 0.0, 0.0}, Axis(0, fx)).axial;
      EXPECT_NEAR(std::abs(got), std::abs(expect), release * fx * l * w / ei) << i << " " << s;
    }
  }
}

// A vertical rim spring c_z in series with each guided spoke: K_zz = n/(L³/(12 E I_y) + c_z), and
// the spoke still bends as a guided beam, root moment (Fz/n)·L/2, whatever the spring.
TEST_P(FlexureSpokes, VerticalRimComplianceActsInSeriesWithTheGuidedSpokes) {
  const int n = GetParam();
  FlexureGeometry g = Spokes(n);
  g.rim_compliance = {0, 0, 2e-7, 0, 0, 0};
  const FlexureBody body(g);
  const double l = body.beam_length_m();
  const double ei = kE * body.section().iy_m4;
  const double per_spoke = l * l * l / (12 * ei) + 2e-7;
  EXPECT_NEAR(body.Stiffness()(2, 2), n / per_spoke, 1e-9 * n / per_spoke);
  const double fz = 90.0;
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(body.SectionAt(i, 0.0, Axis(2, fz)).my, fz / n * l / 2, 1e-9 * fz * l);
  }
}

INSTANTIATE_TEST_SUITE_P(ThreeAndFourSpokes, FlexureSpokes, ::testing::Values(3, 4));

}  // namespace
}  // namespace ftstack::sim
