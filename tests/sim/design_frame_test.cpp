// Design frame solver and families against closed forms, an independent assembly and refinement.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/design/design.hpp"
#include "sim/design/families.hpp"
#include "sim/design/frame.hpp"
#include "sim/flexure_body.hpp"

namespace ftstack::sim::design {
namespace {

constexpr double kE = 200e9;
constexpr double kNu = 0.3;

FrameElement Beam(Anchor a, Anchor b, double w, double h) {
  FrameElement e;
  e.a = a;
  e.b = b;
  e.width_m = w;
  e.height_m = h;
  return e;
}

// Cantilever from the ground at x = −L to the platform at the origin, split at a free node:
// tip compliance L³/(3EI), L/(EA), L/(EI) rotation (Gere & Timoshenko).
TEST(DesignFrame, CantileverMatchesClosedForm) {
  const double l = 0.05, w = 0.006, h = 0.004;
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  f.nodes_m.push_back({-0.3 * l, 0, 0});
  f.elements.push_back(Beam({kGround, -1, {-l, 0, 0}}, {-1, 0, {}}, w, h));
  f.elements.push_back(Beam({-1, 0, {}}, {kPlatform, -1, {0, 0, 0}}, w, h));
  const FrameSolution s(f);
  const double iy = w * h * h * h / 12, iz = h * w * w * w / 12;
  const Mat6& c = s.Compliance();
  EXPECT_NEAR(c(0, 0), l / (kE * w * h), 1e-9 * c(0, 0));
  EXPECT_NEAR(c(2, 2), l * l * l / (3 * kE * iy), 1e-9 * c(2, 2));
  EXPECT_NEAR(c(1, 1), l * l * l / (3 * kE * iz), 1e-9 * c(1, 1));
  EXPECT_NEAR(c(4, 4), l / (kE * iy), 1e-9 * c(4, 4));
  // Root bending strain under Fz = 1 N: M = F·L at the clamp, ε = M·(h/2)/(E·Iy).
  const Row6 eps = s.AxialStrain(0, 0.0, 0, 0.5 * h);
  EXPECT_NEAR(std::abs(eps(2)), l * 0.5 * h / (kE * iy), 1e-9 * std::abs(eps(2)));
}

// Parallelogram of two leaves (length L, d apart) from the ground to the platform: rotation about
// y: k_θ = EA·d²/(2L) + 8EI/L; translation z with rotation free: 24EI/L³ − (12EI/L²)²/k_θ.
TEST(DesignFrame, ParallelogramMatchesClosedForm) {
  const double l = 0.03, w = 0.02, t = 0.001, d = 0.04;
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  for (double z : {0.5 * d, -0.5 * d}) {
    f.elements.push_back(Beam({kGround, -1, {-l, 0, z}}, {kPlatform, -1, {0, 0, z}}, w, t));
  }
  const FrameSolution s(f);
  const double ei = kE * w * t * t * t / 12, ea = kE * w * t;
  const double k_rot = ea * d * d / (2 * l) + 8 * ei / l;
  const double k_z = 24 * ei / (l * l * l) - std::pow(12 * ei / (l * l), 2) / k_rot;
  EXPECT_NEAR(s.Stiffness()(4, 4), k_rot, 1e-9 * k_rot);
  EXPECT_NEAR(1.0 / s.Compliance()(2, 2), k_z, 1e-9 * k_z);
  // Guided leaf: root strain ≈ (F/2)·(L/2)·(t/2)/(EI); the pair holds the rotation only to
  // (12EI/L²)²/(k_θ·24EI/L³) ≈ 0.85 % here, hence 1.5 %.
  const double guided = 0.5 * 0.5 * l * 0.5 * t / ei;
  EXPECT_NEAR(std::abs(s.AxialStrain(0, 0, 0, 0.5 * t)(2)), guided, 1.5e-2 * guided);
}

// The frame assembly reproduces FlexureBody (an independent hub-and-rim implementation).
TEST(DesignFrame, HubSpokeMatchesFlexureBody) {
  FlexureGeometry g;
  g.beam_count = 4;
  g.hub_radius_m = 0.015;
  g.rim_radius_m = 0.04;
  g.beam_width_m = 0.006;
  g.beam_height_m = 0.004;
  g.e_pa = kE;
  g.poisson = kNu;
  const FlexureBody body(g);
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  for (int i = 0; i < 4; ++i) {
    const double th = i * std::numbers::pi / 2;
    const Eigen::Vector3d dir(std::cos(th), std::sin(th), 0);
    f.elements.push_back(Beam({kPlatform, -1, g.hub_radius_m * dir},
                              {kGround, -1, g.rim_radius_m * dir}, g.beam_width_m,
                              g.beam_height_m));
  }
  const FrameSolution s(f);
  const Mat6 diff = s.Stiffness() - body.Stiffness();
  EXPECT_LT(diff.norm(), 1e-9 * body.Stiffness().norm());
  const GaugeSite site{1, 0.01, BeamFace::kTop, 0, 0};
  const Row6 ref = body.StrainMatrix(site).row(0);
  EXPECT_LT((s.AxialStrain(1, 0.01, 0, 0.5 * g.beam_height_m) - ref).norm(), 1e-9 * ref.norm());
}

// Exact beam elements: splitting each leaf into 5 elements changes nothing (mesh refinement).
TEST(DesignFrame, GuidedFamilyIsMeshIndependent) {
  GuidedParams p;
  const Readout r;
  const DesignModel coarse = Guided(p, r);
  p.elements_per_leaf = 5;
  const DesignModel fine = Guided(p, r);
  EXPECT_LT((coarse.stiffness - fine.stiffness).norm(), 1e-8 * coarse.stiffness.norm());
  EXPECT_LT((coarse.sensitivity_mvv - fine.sensitivity_mvv).norm(),
            1e-8 * coarse.sensitivity_mvv.norm());
}

// The guided family decouples: force bridges do not see moments and vice versa (calibration
// diagonal), and the tilting stiffness exceeds the lateral one by the parallelogram lever.
TEST(DesignFrame, GuidedFamilyDecouplesForcesFromMoments) {
  const DesignModel m = Guided(GuidedParams{}, Readout{});
  const Eigen::MatrixXd& s = m.sensitivity_mvv;
  for (int b = 0; b < 3; ++b) {
    EXPECT_LT(s.row(b).tail<3>().cwiseAbs().maxCoeff(),
              1e-2 * s.row(b).head<3>().cwiseAbs().maxCoeff());
  }
  const DesignFigures f = Evaluate(m, DesignOptions{});
  EXPECT_GT(f.capacity(3) / f.capacity(0), 0.2);  // hub-spoke bodies reach ~0.05 m
}

// The guided family against hand formulas (independent of the frame solver): under Fz the four
// z-stage leaves S-bend as guided beams, each carrying Fz/4: ε(s) = (Fz/4)·(L/2 − s)·(t/2)/(E·I)
// at distance s from the root; under My the z-stage parallelograms turn it into leaf push–pull,
// N = My/(2d) per leaf (two parallelograms), ε = N/(E·b·t) at mid-leaf.
TEST(DesignFrame, GuidedGaugeStrainsMatchHandFormulas) {
  GuidedParams p;
  p.leaf_length_m = 0.04;
  p.leaf_width_m = 0.03;
  p.leaf_thickness_z_m = 0.0012;
  p.separation_m = 0.06;
  const DesignModel m = Guided(p, Readout{});
  const double e = p.material.e_pa, b = p.leaf_width_m, t = p.leaf_thickness_z_m;
  const double l = p.leaf_length_m, s = p.gauge_frac * l;
  const double i = b * t * t * t / 12;
  const double bend = 0.25 * (0.5 * l - s) * 0.5 * t / (e * i);
  EXPECT_NEAR(std::abs(m.gauge_strain(0, 2)), bend, 0.02 * bend);  // z-stage root gauge, per N
  const double push = 1.0 / (2 * p.separation_m) / (e * b * t);
  EXPECT_NEAR(std::abs(m.gauge_strain(12, 4)), push, 0.05 * push);  // z-stage mid-leaf, per N·m
  // The lever the family reaches is the ratio of the two: about (L/2 − s)·d·/t, not a radius.
  EXPECT_GT(std::abs(m.gauge_strain(0, 2)) / std::abs(m.gauge_strain(12, 4)), 0.5);
}

TEST(DesignFigures, PointMassFrequencyAndResolution) {
  Mat6 k = Mat6::Identity() * 1e6;
  const Vec6 f = NaturalFrequenciesHz(k, 4.0, 0.0, 0.5);
  EXPECT_NEAR(f(0), std::sqrt(1e6 / 4.0) / (2 * std::numbers::pi), 1e-9);
  EXPECT_NEAR(f(5), std::sqrt(1e6 / (4.0 * 0.25)) / (2 * std::numbers::pi), 1e-9);
  DesignModel m;
  m.sensitivity_mvv = Eigen::MatrixXd::Identity(6, 6) * 2e-3;
  m.gauge_strain = Eigen::MatrixXd::Identity(6, 6) * 1e-6;
  m.gauge_strain(2, 0) = 1e-6;  // one gauge sees Fx and Fz: the combined rule halves the range
  m.stress_normal = Eigen::MatrixXd::Identity(6, 6) * 1e5;
  m.stress_shear = Eigen::MatrixXd::Zero(1, 6);
  m.stiffness = k;
  m.material = Steel174Ph();
  m.bridge_noise_mvv = 1e-4;
  m.native_bandwidth_hz = 500;
  DesignOptions o;
  o.bandwidth_hz = 125;
  const DesignFigures d = Evaluate(m, o);
  EXPECT_NEAR(d.resolution(0), 1e-4 / 2e-3 * 0.5, 1e-12);  // √(125/500) = 0.5
  EXPECT_NEAR(d.capacity(0), 1e-3 / 1e-6, 1e-6);           // gauge strain binds: 1000 N
  EXPECT_EQ(d.binding[0], Limit::kGaugeStrain);
  EXPECT_NEAR(d.combined_scale, 0.5, 1e-12);  // Fxy and Fz shares both 1: twice the strain
}

}  // namespace
}  // namespace ftstack::sim::design
