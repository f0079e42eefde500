// Flexure body against closed forms: cantilever, guided beams, M·c/(E·I), an independent assembly.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/beam_element.hpp"
#include "sim/flexure_body.hpp"

namespace ftstack::sim {
namespace {

constexpr double kE = 200e9;
constexpr double kNu = 0.3;

FlexureGeometry Geometry(int beams) {
  FlexureGeometry g;
  g.beam_count = beams;
  g.hub_radius_m = 0.015;
  g.rim_radius_m = 0.040;
  g.beam_width_m = 0.006;
  g.beam_height_m = 0.004;
  g.e_pa = kE;
  g.poisson = kNu;
  return g;
}

// Cantilever: node 2 clamped, load at node 1. Textbook tip deflections (Gere & Timoshenko).
TEST(FrameElement, CantileverTipDeflectionMatchesTextbook) {
  const BeamSection s = RectangularSection(kE, kNu, 0.006, 0.004);
  const double l = 0.05;
  const Eigen::Matrix<double, 12, 12> k = FrameElementStiffness(s, l);
  const Eigen::Matrix<double, 6, 6> k11 = k.topLeftCorner<6, 6>();
  const double p = 10.0;
  const double t = 0.5;
  Eigen::Matrix<double, 6, 1> f;
  f << p, p, p, t, 0, 0;
  const Eigen::Matrix<double, 6, 1> u = k11.ldlt().solve(f);
  EXPECT_NEAR(u(0), p * l / (kE * s.area_m2), 1e-12 * std::abs(u(0)) + 1e-18);
  EXPECT_NEAR(u(1), p * l * l * l / (3 * kE * s.iz_m4), 1e-9 * std::abs(u(1)));
  EXPECT_NEAR(u(2), p * l * l * l / (3 * kE * s.iy_m4), 1e-9 * std::abs(u(2)));
  EXPECT_NEAR(u(3), t * l / (s.g_pa * s.j_m4), 1e-9 * std::abs(u(3)));
  // End slopes P·L²/(2EI); free end at x = 0, so w rises toward it: dv/dx < 0, dw/dx < 0,
  // rz = dv/dx and ry = −dw/dx.
  EXPECT_NEAR(u(5), -p * l * l / (2 * kE * s.iz_m4), 1e-9 * std::abs(u(5)));
  EXPECT_NEAR(u(4), p * l * l / (2 * kE * s.iy_m4), 1e-9 * std::abs(u(4)));
}

TEST(FrameElement, StiffnessIsSymmetricWithSixRigidBodyModes) {
  const BeamSection s = RectangularSection(kE, kNu, 0.006, 0.004);
  const Eigen::Matrix<double, 12, 12> k = FrameElementStiffness(s, 0.03);
  EXPECT_LT((k - k.transpose()).norm(), 1e-9 * k.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> es(k);
  int zero = 0;
  for (int i = 0; i < 12; ++i)
    zero += std::abs(es.eigenvalues()(i)) < 1e-9 * es.eigenvalues().maxCoeff();
  EXPECT_EQ(zero, 6);
}

TEST(FrameElement, TorsionConstantOfSquareMatchesTable) {
  // Square: J = 0.1406·a⁴ (Roark; Timoshenko & Goodier k1 = 0.141).
  EXPECT_NEAR(RectangleTorsionConstant(1.0, 1.0), 0.1406, 0.0006);
  // Thin strip: J → a·b³/3.
  EXPECT_NEAR(RectangleTorsionConstant(1.0, 0.01) / (1.0 * 1e-6 / 3.0), 1.0, 0.01);
}

class FlexureBeams : public ::testing::TestWithParam<int> {};

TEST_P(FlexureBeams, SymmetricFzIsSharedEquallyAndBeamsAreGuided) {
  const int n = GetParam();
  const FlexureBody body(Geometry(n));
  Wrench w = Wrench::Zero();
  w(2) = 300.0;
  const auto d = body.HubDisplacement(w);
  const double l = body.beam_length_m();
  const BeamSection& s = body.section();
  // n guided-guided beams in parallel: k = n·12EI/L³; no hub rotation or in-plane motion.
  EXPECT_NEAR(d(2), w(2) * l * l * l / (n * 12 * kE * s.iy_m4), 1e-9 * d(2));
  EXPECT_LT(d.segment<3>(3).norm(), 1e-12);
  EXPECT_LT(d.head<2>().norm(), 1e-9 * d(2));
  for (int i = 0; i < n; ++i) {
    const auto f = body.BeamEndForces(i, w);
    EXPECT_NEAR(f(2), w(2) / n, 1e-9 * w(2)) << "beam " << i;
    // Guided beam: end moments F·l/2 of opposite sense at the two ends.
    const double m_root = body.SectionAt(i, 0.0, w).my;
    const double m_tip = body.SectionAt(i, l, w).my;
    EXPECT_NEAR(m_root, w(2) / n * l / 2, 1e-9 * w(2) * l) << "beam " << i;
    EXPECT_NEAR(m_tip, -w(2) / n * l / 2, 1e-9 * w(2) * l) << "beam " << i;
    EXPECT_NEAR(body.SectionAt(i, 0.5 * l, w).my, 0.0, 1e-9 * w(2) * l);
  }
}

TEST_P(FlexureBeams, SurfaceStrainIsMcOverEI) {
  const int n = GetParam();
  const FlexureBody body(Geometry(n));
  Wrench w = Wrench::Zero();
  w(2) = 250.0;
  const double l = body.beam_length_m();
  const double h = body.geometry().beam_height_m;
  const double iy = body.section().iy_m4;
  for (double frac : {0.0, 0.2, 0.7, 1.0}) {
    const double m = w(2) / n * (l / 2 - frac * l);  // guided-beam moment at that section
    const double expect = m * (h / 2) / (kE * iy);
    GaugeSite top{1, frac * l, BeamFace::kTop, 0.0, 0.0};
    GaugeSite bottom{1, frac * l, BeamFace::kBottom, 0.0, 0.0};
    const GaugeStrain et = body.StrainAt(top, w);
    EXPECT_NEAR(et.axial, expect, 1e-9 * std::abs(w(2) * l * h / (kE * iy)));
    EXPECT_NEAR(et.transverse, -kNu * expect, 1e-9 * std::abs(w(2) * l * h / (kE * iy)));
    EXPECT_NEAR(body.StrainAt(bottom, w).axial, -expect, 1e-9 * std::abs(w(2) * l * h / (kE * iy)));
    // A gauge at 45° sees the mean of the normal strains (no shear on the top face under Fz):
    // ε45 = (εx + εs)/2 = (1 − ν)·εx/2.
    GaugeSite diag{1, frac * l, BeamFace::kTop, 0.0, 45.0};
    EXPECT_NEAR(body.StrainAt(diag, w).axial, (1 - kNu) * expect / 2,
                1e-9 * std::abs(w(2) * l * h / (kE * iy)));
  }
}

TEST_P(FlexureBeams, SuperpositionOfLoads) {
  const FlexureBody body(Geometry(GetParam()));
  Wrench a;
  a << 30, -50, 120, 2.0, -1.5, 0.7;
  Wrench b;
  b << -80, 20, -60, -0.5, 3.0, -2.0;
  const GaugeSite site{0, 0.004, BeamFace::kPlusY, 0.001, 30.0};
  const GaugeStrain ea = body.StrainAt(site, a);
  const GaugeStrain eb = body.StrainAt(site, b);
  const GaugeStrain eab = body.StrainAt(site, a + b);
  const double scale = std::abs(ea.axial) + std::abs(eb.axial);
  EXPECT_NEAR(eab.axial, ea.axial + eb.axial, 1e-12 * scale);
  EXPECT_NEAR(eab.transverse, ea.transverse + eb.transverse, 1e-12 * scale);
  // Equilibrium: the beams' hub-end forces balance the applied wrench about the hub centre.
  Wrench sum = Wrench::Zero();
  for (int i = 0; i < body.beam_count(); ++i) {
    const double th = 2 * std::numbers::pi * i / body.beam_count();
    Eigen::Matrix3d r;
    r << std::cos(th), std::sin(th), 0, -std::sin(th), std::cos(th), 0, 0, 0, 1;
    const auto f = body.BeamEndForces(i, a);
    const Eigen::Vector3d fg = r.transpose() * f.head<3>();
    const Eigen::Vector3d mg = r.transpose() * f.segment<3>(3);
    const Eigen::Vector3d p = body.geometry().hub_radius_m * r.row(0).transpose();
    sum.head<3>() += fg;
    sum.tail<3>() += mg + p.cross(fg);
  }
  EXPECT_LT((sum - a).norm(), 1e-9 * a.norm());
}

TEST_P(FlexureBeams, MzIsSharedAsEqualTangentialForces) {
  const int n = GetParam();
  const FlexureBody body(Geometry(n));
  Wrench w = Wrench::Zero();
  w(5) = 6.0;
  const auto d = body.HubDisplacement(w);
  EXPECT_LT(d.head<5>().norm(), 1e-9 * std::abs(d(5)));
  const double fy0 = body.BeamEndForces(0, w)(1);
  const double mz0 = body.BeamEndForces(0, w)(5);
  for (int i = 1; i < n; ++i) {
    EXPECT_NEAR(body.BeamEndForces(i, w)(1), fy0, 1e-9 * std::abs(fy0));
  }
  EXPECT_NEAR(n * (fy0 * body.geometry().hub_radius_m + mz0), w(5), 1e-9 * w(5));
}

INSTANTIATE_TEST_SUITE_P(ThreeAndFourBeams, FlexureBeams, ::testing::Values(3, 4));

// The hub stiffness by static condensation against a direct solve of the whole system (hub plus
// every rim node on its springs), assembled here independently from the element matrices.
TEST(FlexureBody, CondensedRimComplianceMatchesFullAssembly) {
  FlexureGeometry g = Geometry(3);
  g.rim_compliance = {2e-7, 0, 5e-8, 0, 1e-3, 0};
  const FlexureBody body(g);
  const int n = g.beam_count;
  const int dof = 6 + 6 * n;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(dof, dof);
  const BeamSection s = RectangularSection(g.e_pa, g.poisson, g.beam_width_m, g.beam_height_m);
  const auto kl = FrameElementStiffness(s, g.rim_radius_m - g.hub_radius_m);
  for (int i = 0; i < n; ++i) {
    const double th = 2 * std::numbers::pi * i / n;
    Eigen::Matrix3d r;
    r << std::cos(th), std::sin(th), 0, -std::sin(th), std::cos(th), 0, 0, 0, 1;
    const Eigen::Vector3d p = g.hub_radius_m * r.row(0).transpose();
    // Element DOFs (local) as a function of global unknowns: hub (rigid body) and rim node (local).
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(12, dof);
    Eigen::Matrix3d px;
    px << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
    a.block<3, 3>(0, 0) = r;
    a.block<3, 3>(0, 3) = -r * px;
    a.block<3, 3>(3, 3) = r;
    a.block<6, 6>(6, 6 + 6 * i).setIdentity();
    k += a.transpose() * kl * a;
    for (int j = 0; j < 6; ++j) {
      const double c = g.rim_compliance[static_cast<std::size_t>(j)];
      // Rigid directions: a very stiff spring (1e6 × the element's own stiffness).
      k(6 + 6 * i + j, 6 + 6 * i + j) += c > 0 ? 1.0 / c : 1e6 * kl(j + 6, j + 6);
    }
  }
  Wrench w;
  w << 40, -70, 150, 1.2, -2.5, 3.0;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dof);
  f.head<6>() = w;
  const Eigen::VectorXd u = k.ldlt().solve(f);
  const auto d = body.HubDisplacement(w);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(d(j), u(j), 1e-5 * d.cwiseAbs().maxCoeff()) << j;
}

TEST(FlexureBody, RejectsBadGeometry) {
  FlexureGeometry g = Geometry(3);
  g.beam_count = 5;
  EXPECT_THROW(FlexureBody{g}, std::invalid_argument);
  g = Geometry(3);
  g.rim_radius_m = g.hub_radius_m;
  EXPECT_THROW(FlexureBody{g}, std::invalid_argument);
  g = Geometry(3);
  g.beam_height_m = std::nan("");
  EXPECT_THROW(FlexureBody{g}, std::invalid_argument);
  const FlexureBody ok(Geometry(3));
  EXPECT_THROW((void)ok.StrainAt({0, 1.0, BeamFace::kTop, 0, 0}, Wrench::Zero()),
               std::invalid_argument);
  EXPECT_THROW((void)ok.StrainAt({3, 0.01, BeamFace::kTop, 0, 0}, Wrench::Zero()),
               std::invalid_argument);
  EXPECT_THROW((void)ok.StrainAt({0, 0.01, BeamFace::kTop, 0.01, 0}, Wrench::Zero()),
               std::invalid_argument);
}

}  // namespace
}  // namespace ftstack::sim
