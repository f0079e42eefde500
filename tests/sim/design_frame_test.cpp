// Design frame solver and families against closed forms, an independent assembly and refinement.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/design/design.hpp"
#include "sim/design/families.hpp"
#include "sim/design/frame.hpp"
#include "sim/flexure_body.hpp"
#include "sim/physical_sensor.hpp"
#include "sim/sensor_description.hpp"

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
  f.shear_deformable = false;
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
  f.shear_deformable = false;
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
  f.shear_deformable = false;
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

// Timoshenko cantilever (Timoshenko & Gere): tip deflection P·L³/(3EI) + P·L/(κGA), κ = 5/6,
// tip rotation under a tip moment M·L/(EI) unchanged, root strain M·c/(EI) unchanged (statics).
// A stubby beam (L/h = 2) so that shear is 14 % of the deflection and a 1 % slip would show.
TEST(DesignFrame, TimoshenkoCantileverMatchesClosedForm) {
  const double l = 0.02, w = 0.006, h = 0.01;
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  f.nodes_m.push_back({-0.6 * l, 0, 0});
  f.elements.push_back(Beam({kGround, -1, {-l, 0, 0}}, {-1, 0, {}}, w, h));
  f.elements.push_back(Beam({-1, 0, {}}, {kPlatform, -1, {0, 0, 0}}, w, h));
  const FrameSolution s(f);
  const double iy = w * h * h * h / 12, iz = h * w * w * w / 12;
  const double kga = 5.0 / 6.0 * kE / (2 * (1 + kNu)) * w * h;
  const Mat6& c = s.Compliance();
  const double wz = l * l * l / (3 * kE * iy) + l / kga;
  const double wy = l * l * l / (3 * kE * iz) + l / kga;
  EXPECT_NEAR(c(2, 2), wz, 1e-9 * wz);
  EXPECT_NEAR(c(1, 1), wy, 1e-9 * wy);
  EXPECT_GT((l / kga) / wz, 0.1);  // the shear term matters here
  EXPECT_NEAR(c(4, 4), l / (kE * iy), 1e-9 * c(4, 4));
  EXPECT_NEAR(c(0, 0), l / (kE * w * h), 1e-9 * c(0, 0));
  const Row6 eps = s.AxialStrain(0, 0.0, 0, 0.5 * h);
  EXPECT_NEAR(std::abs(eps(2)), l * 0.5 * h / (kE * iy), 1e-9 * std::abs(eps(2)));
}

// A leaf wider than it is long bends through its thickness as a plate: E/(1 − ν²) in the bending
// term (not in shear or in the in-plane bending), and its surface strain is σ(1 − ν²)/E.
TEST(DesignFrame, WideLeafUsesThePlateFactor) {
  const double l = 0.02, b = 0.05, t = 0.001;
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  f.elements.push_back(Beam({kGround, -1, {-l, 0, 0}}, {kPlatform, -1, {0, 0, 0}}, b, t));
  const FrameSolution s(f);
  const double ep = kE / (1 - kNu * kNu);
  const double iy = b * t * t * t / 12, iz = t * b * b * b / 12;
  const double kga = 5.0 / 6.0 * kE / (2 * (1 + kNu)) * b * t;
  const double wz = l * l * l / (3 * ep * iy) + l / kga;
  const double wy = l * l * l / (3 * kE * iz) + l / kga;
  EXPECT_NEAR(s.Compliance()(2, 2), wz, 1e-9 * wz);
  EXPECT_NEAR(s.Compliance()(1, 1), wy, 1e-9 * wy);
  const double eps = l * 0.5 * t / (ep * iy);
  EXPECT_NEAR(std::abs(s.AxialStrain(0, 0, 0, 0.5 * t)(2)), eps, 1e-9 * eps);
  const double sigma = l * 0.5 * t / iy;
  EXPECT_NEAR(std::abs(s.NormalStress(0, 0, 0, 0.5 * t)(2)), sigma, 1e-9 * sigma);
}

// FlexureBody's Timoshenko path against the frame's (two assemblies, one element formula each
// tested above), and the slender-beam flag: L/h = 3.5 passes, L/h = 1.2 is flagged.
TEST(DesignFrame, HubSpokeTimoshenkoAndSlenderFlag) {
  FlexureGeometry g;
  g.beam_count = 3;
  g.hub_radius_m = 0.015;
  g.rim_radius_m = 0.027;
  g.beam_width_m = 0.008;
  g.beam_height_m = 0.01;
  g.e_pa = kE;
  g.poisson = kNu;
  g.shear_deformable = true;
  const FlexureBody body(g);
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  for (int i = 0; i < 3; ++i) {
    const double th = i * 2 * std::numbers::pi / 3;
    const Eigen::Vector3d dir(std::cos(th), std::sin(th), 0);
    f.elements.push_back(Beam({kPlatform, -1, g.hub_radius_m * dir},
                              {kGround, -1, g.rim_radius_m * dir}, g.beam_width_m,
                              g.beam_height_m));
  }
  const FrameSolution s(f);
  EXPECT_LT((s.Stiffness() - body.Stiffness()).norm(), 1e-9 * body.Stiffness().norm());
  g.shear_deformable = false;
  EXPECT_GT(FlexureBody(g).Stiffness()(2, 2), 1.2 * body.Stiffness()(2, 2));  // L/h = 1.2
  const Readout r;
  HubSpokeParams p;
  p.hub_radius_m = 0.015;
  p.rim_radius_m = 0.05;
  EXPECT_EQ(HubSpoke(p, r).beam_validity, "");
  p.rim_radius_m = 0.027;
  EXPECT_EQ(HubSpoke(p, r).beam_validity, "L/h = 1.20 < 2");
  GuidedParams q;
  q.leaf_length_m = 0.01;
  q.leaf_width_m = 0.05;
  EXPECT_EQ(Guided(q, r).beam_validity, "z stage leaves: L/b = 0.20 < 0.5");
}

// Elastic roots through the frame's element joints: each beam split at a free node, the hub
// joint on the first element's end a and the rim joint on the second's end b, against the
// flexure body's own assembly (whose Kzz is checked against the guided-beam closed form in
// beam_root_test.cpp); strains along the beam follow.
TEST(DesignFrame, ElementJointsMatchFlexureBodyElasticRoots) {
  FlexureGeometry g;
  g.beam_count = 4;
  g.hub_radius_m = 0.015;
  g.rim_radius_m = 0.05;
  g.beam_width_m = 0.008;
  g.beam_height_m = 0.01;
  g.e_pa = kE;
  g.poisson = kNu;
  g.shear_deformable = true;
  g.elastic_roots = true;
  const FlexureBody body(g);
  FrameModel f;
  f.e_pa = kE;
  f.poisson = kNu;
  const EndCompliance root = BuiltInRootCompliance(kE, g.beam_width_m, g.beam_height_m);
  const double split = 0.4 * (g.rim_radius_m - g.hub_radius_m);
  for (int i = 0; i < 4; ++i) {
    const double th = i * std::numbers::pi / 2;
    const Eigen::Vector3d dir(std::cos(th), std::sin(th), 0);
    f.nodes_m.push_back((g.hub_radius_m + split) * dir);
    FrameElement inner =
        Beam({kPlatform, -1, g.hub_radius_m * dir}, {-1, i, {}}, g.beam_width_m, g.beam_height_m);
    FrameElement outer =
        Beam({-1, i, {}}, {kGround, -1, g.rim_radius_m * dir}, g.beam_width_m, g.beam_height_m);
    inner.member_length_m = outer.member_length_m = g.rim_radius_m - g.hub_radius_m;
    inner.joint_a = root;
    outer.joint_b = root;
    f.elements.push_back(inner);
    f.elements.push_back(outer);
  }
  const FrameSolution s(f);
  EXPECT_LT((s.Stiffness() - body.Stiffness()).norm(), 1e-9 * body.Stiffness().norm());
  g.elastic_roots = false;
  EXPECT_LT(body.Stiffness()(2, 2), 0.8 * FlexureBody(g).Stiffness()(2, 2));
  const double z = 0.5 * g.beam_height_m;
  for (double at : {0.0, 0.3 * split}) {
    const Eigen::Matrix<double, 1, 6> expect =
        body.StrainMatrix(GaugeSite{0, at, BeamFace::kTop, 0, 0}).row(0);
    EXPECT_LT((s.AxialStrain(0, at, 0, z) - expect).norm(), 1e-9 * expect.norm()) << at;
  }
}

// The project's default body: its in-plane bridge's grids sit on the side faces' mid-height line
// (the out-of-plane neutral axis), so no out-of-plane load (Fz, Mx, My) strains them — off that
// line they also read the restrained-warping strain of twisted beams that beam theory lacks
// (docs/design.md). The top and bottom grids do carry those loads.
TEST(DesignFrame, DefaultBodyInPlaneGridsSitOnTheNeutralAxis) {
  const auto phys = ParsePhysicalSensor(DefaultSensorJson(), "builtin");
  const DesignModel m = FromPhysicalSensor(*phys, Aluminium7075(), 1e-4, 1000);
  double top = 0;
  for (Eigen::Index i = 0; i < m.gauge_strain.rows(); ++i)
    top = std::max(top, m.gauge_strain.row(i).segment(2, 3).cwiseAbs().maxCoeff());
  ASSERT_GT(top, 0);
  int side = 0;
  for (std::size_t i = 0; i < m.gauges.size(); ++i) {
    if (std::abs(m.gauges[i].normal.z()) > 0.5) continue;  // top or bottom face
    ++side;
    EXPECT_NEAR(m.gauges[i].point_m.z(), 0.0, 1e-12) << m.gauges[i].name;
    const Row6 row = m.gauge_strain.row(static_cast<Eigen::Index>(i));
    EXPECT_LT(row.segment(2, 3).cwiseAbs().maxCoeff(), 1e-9 * top) << m.gauges[i].name;
    EXPECT_GT(std::abs(row(5)), 0.1 * top) << m.gauges[i].name;  // Mz bends them in plane
  }
  EXPECT_EQ(side, 12);
}

// Gauge rows by position: row i of the guided family's gauge matrix is the gauge its documented
// place names (computed here from the frame, not through the family's lambda), whatever order the
// compiler evaluates function arguments in.
TEST(DesignFrame, GuidedGaugeRowsAreInTheDocumentedOrder) {
  GuidedParams p;
  const DesignModel m = Guided(p, Readout{});
  const FrameSolution sol(GuidedFrame(p));
  ASSERT_EQ(m.gauge_strain.rows(), 24);
  ASSERT_EQ(m.gauges.size(), 24u);
  const double root = p.gauge_frac * p.leaf_length_m, mid = 0.5 * p.leaf_length_m;
  for (int st = 0; st < 3; ++st) {
    const double t = st == 0 ? p.leaf_thickness_z_m : p.leaf_thickness_m;
    // Leaf index stage·4 + side·2 + leaf (one element per leaf).
    const int plus_upper = st * 4, minus_upper = st * 4 + 2, plus_lower = st * 4 + 1;
    const Row6 force[4] = {sol.AxialStrain(plus_upper, root, 0, 0.5 * t),
                           sol.AxialStrain(plus_upper, root, 0, -0.5 * t),
                           sol.AxialStrain(minus_upper, root, 0, 0.5 * t),
                           sol.AxialStrain(minus_upper, root, 0, -0.5 * t)};
    const Row6 moment[4] = {sol.AxialStrain(plus_upper, mid, 0, 0.5 * t),
                            sol.AxialStrain(plus_upper, mid, 0, -0.5 * t),
                            sol.AxialStrain(plus_lower, mid, 0, 0.5 * t),
                            sol.AxialStrain(plus_lower, mid, 0, -0.5 * t)};
    for (int k = 0; k < 4; ++k) {
      const Row6 got_f = m.gauge_strain.row(4 * st + k);
      const Row6 got_m = m.gauge_strain.row(12 + 4 * st + k);
      EXPECT_LT((got_f - force[k]).norm(), 1e-12 * force[k].norm()) << "stage " << st << " " << k;
      EXPECT_LT((got_m - moment[k]).norm(), 1e-12 * moment[k].norm()) << "stage " << st << " " << k;
    }
    // The grid of row 0 of each stage lies on the + side upper leaf's top face near its outer
    // root: along the leaf axis, at the + compliant-axis offset d/2 + t/2.
    const GaugeGrid& g = m.gauges[static_cast<std::size_t>(4 * st)];
    const Eigen::Vector3d c = st == 0
                                  ? Eigen::Vector3d::UnitZ()
                                  : (st == 1 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY());
    EXPECT_NEAR(g.point_m.dot(c), 0.5 * p.separation_m + 0.5 * t, 1e-12);
    EXPECT_NEAR(g.normal.dot(c), 1.0, 1e-12);
  }
  // Under Fz the z-stage top and bottom faces at the root are equal and opposite.
  EXPECT_NEAR(m.gauge_strain(0, 2), -m.gauge_strain(1, 2), 1e-9 * std::abs(m.gauge_strain(0, 2)));
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
