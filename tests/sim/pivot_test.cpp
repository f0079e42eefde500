// Tests of the crossed-strip pivot solvers against closed forms and against each other.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <tuple>

#include "sim/pivot/pivot.hpp"

namespace ftstack::sim::pivot {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The seed report's strip: E 200 GPa, L 98 mm, b 13 mm, t 0.5 mm (defaults of PivotGeometry).
PivotGeometry ReportStrip(double alpha_deg = 45.0, double lambda = 0.5) {
  PivotGeometry g;
  g.e_pa = 200e9;
  g.length_m = 0.098;
  g.width_m = 0.013;
  g.thickness_m = 0.5e-3;
  g.alpha_rad = alpha_deg * kDeg;
  g.crossing_fraction = lambda;
  return g;
}

PivotResult Exact(const PivotGeometry& g, double theta_deg, double v, double h) {
  return SolvePivot(g, {theta_deg * kDeg, v, h}, PivotMethod::kExact);
}

// ---- The elastica integrator against closed forms ------------------------------------------

TEST(PivotElastica, PureMomentBendsIntoACircularArc) {
  // m' = 0 without end force: constant curvature m0, the end lies on a circle of radius 1/m0.
  for (const double m0 : {0.3, 1.0, 2.5}) {
    const double phi0 = 0.4;
    const ElasticaEnd e = IntegrateElastica(phi0, m0, 0.0, 0.0, 0.0, 0.0, 200);
    const double r = 1.0 / m0;
    EXPECT_NEAR(e.phi, phi0 + m0, 1e-12);
    EXPECT_NEAR(e.x, r * (std::sin(phi0 + m0) - std::sin(phi0)), 1e-10);
    EXPECT_NEAR(e.y, -r * (std::cos(phi0 + m0) - std::cos(phi0)), 1e-10);
    EXPECT_NEAR(e.max_abs_m, m0, 1e-12);
  }
}

TEST(PivotElastica, SensitivityMatchesFiniteDifferences) {
  const double p[3] = {0.7, -3.0, 5.0};
  const ElasticaEnd base = IntegrateElastica(1.1, p[0], 0.0, 0.0, p[1], p[2], 200);
  for (int k = 0; k < 3; ++k) {
    double q[3] = {p[0], p[1], p[2]};
    const double h = 1e-6;
    q[k] += h;
    const ElasticaEnd plus = IntegrateElastica(1.1, q[0], 0.0, 0.0, q[1], q[2], 200);
    q[k] -= 2 * h;
    const ElasticaEnd minus = IntegrateElastica(1.1, q[0], 0.0, 0.0, q[1], q[2], 200);
    const double fd[4] = {(plus.phi - minus.phi) / (2 * h), (plus.m - minus.m) / (2 * h),
                          (plus.x - minus.x) / (2 * h), (plus.y - minus.y) / (2 * h)};
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(base.sensitivity(r, k), fd[r], 1e-7) << r << "," << k;
  }
}

// ---- Closed forms of the pivot -----------------------------------------------------------------

// Small-deflection theory (cubic strip shapes, rotation about O, inextensible strips) gives for
// crossing fraction lambda:
//   stiffness    K0 = 8·EI/L·(1 − 3λ + 3λ²)                (2·EI/L at λ = ½)
//   centre shift dY = k(λ)·L·θ²/cos α, k(λ) = 0.6·λ(1−λ) − 1/15   (L·θ²/(12·cos α) at λ = ½)
// and, by the energy theorem, the first-order effect of the axial load V on the stiffness is
// −V·d²(dY)/dθ², i.e. K = K0 − 2·k(λ)·V·L/cos α  (= 2EI/L·[1 − V·L²/(12·EI·cos α)] at λ = ½).
double ShiftCoefficient(double lambda) { return 0.6 * lambda * (1 - lambda) - 1.0 / 15.0; }

TEST(PivotClosedForm, StiffnessAtZeroLoadIsEightEIOverLTimesCrossingPolynomial) {
  for (const double lambda : {0.5, 0.3, 0.2}) {
    for (const double alpha : {30.0, 45.0, 60.0}) {
      const PivotGeometry g = ReportStrip(alpha, lambda);
      const double ei = g.BendingStiffness(), l = g.length_m;
      const double k0 = 8 * ei / l * (1 - 3 * lambda + 3 * lambda * lambda);
      const PivotResult r = Exact(g, 0.2, 0.0, 0.0);
      ASSERT_TRUE(r.valid) << r.reason;
      // Relative corrections are O(θ²) ≈ 1e-5 at 0.2°.
      EXPECT_NEAR(r.dc_dtheta_nm_per_rad / k0, 1.0, 1e-4) << "lambda " << lambda;
      EXPECT_NEAR(r.c_nm / (k0 * 0.2 * kDeg), 1.0, 1e-4);
    }
  }
}

TEST(PivotClosedForm, CentreShiftIsLThetaSquaredOver12CosAlpha) {
  for (const double alpha : {30.0, 45.0, 60.0}) {
    for (const double theta : {1.0, 3.0}) {
      const PivotGeometry g = ReportStrip(alpha);
      const double th = theta * kDeg;
      const double expected = g.length_m * th * th / (12 * std::cos(g.alpha_rad));
      const PivotResult r = Exact(g, theta, 0.0, 0.0);
      ASSERT_TRUE(r.valid) << r.reason;
      // The next term is O(θ²) relative (≈ 3e-3 at 3°); dX is O(θ³).
      EXPECT_NEAR(r.dy_m / expected, 1.0, 4e-3) << "alpha " << alpha << " theta " << theta;
      EXPECT_LT(std::abs(r.dx_m), 0.05 * expected);
      EXPECT_GT(r.dy_m, 0.0);  // the body moves away from the base
    }
  }
  // The generalised coefficient at another crossing point (independent of the λ = ½ case).
  const PivotGeometry g = ReportStrip(45.0, 0.3);
  const double th = 1.0 * kDeg;
  const PivotResult r = Exact(g, 1.0, 0.0, 0.0);
  EXPECT_NEAR(r.dy_m / (ShiftCoefficient(0.3) * g.length_m * th * th / std::cos(g.alpha_rad)), 1.0,
              5e-3);
}

double SmallAngleStiffness(const PivotGeometry& g, double v) {
  const PivotResult r = Exact(g, 0.2, v, 0.0);
  EXPECT_TRUE(r.converged);
  return r.dc_dtheta_nm_per_rad;
}

TEST(PivotClosedForm, AxialTensionSoftensAndCompressionStiffensToFirstOrder) {
  for (const double alpha : {30.0, 45.0, 60.0}) {
    const PivotGeometry g = ReportStrip(alpha);
    const double ei = g.BendingStiffness(), l = g.length_m, ca = std::cos(g.alpha_rad);
    // d K / d V from K = 2EI/L·[1 − V·L²/(12·EI·cos α)]:
    const double slope_closed = -2 * ei / l * l * l / (12 * ei * ca);
    const double dv = 0.5;  // N; central difference, the O(dV²) error is below 1e-4 relative
    const double slope = (SmallAngleStiffness(g, dv) - SmallAngleStiffness(g, -dv)) / (2 * dv);
    EXPECT_NEAR(slope / slope_closed, 1.0, 2e-3) << "alpha " << alpha;
    // The sign, stated: tension (V > 0) softens, compression (V < 0) stiffens.
    const double k0 = SmallAngleStiffness(g, 0.0);
    EXPECT_LT(SmallAngleStiffness(g, 5.0), k0);
    EXPECT_GT(SmallAngleStiffness(g, -5.0), k0);
  }
}

TEST(PivotClosedForm, LoadIndependentCrossingPointIsNear0127) {
  // Closed form: k(λ) = 0 ⇔ λ² − λ + 1/9 = 0 ⇔ λ = (1 − √5/3)/2 = 0.12732.
  const double lambda_closed = 0.5 * (1 - std::sqrt(5.0) / 3.0);
  // Exact solver: the λ where dK/dV = 0, by bisection on the sign of the load sensitivity.
  auto load_slope = [](double lambda) {
    const PivotGeometry g = ReportStrip(45.0, lambda);
    return SmallAngleStiffness(g, 1.0) - SmallAngleStiffness(g, -1.0);
  };
  double lo = 0.05, hi = 0.3;
  const double s_lo = load_slope(lo);
  ASSERT_LT(s_lo * load_slope(hi), 0.0);
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (load_slope(mid) * s_lo > 0) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  EXPECT_NEAR(0.5 * (lo + hi), lambda_closed, 1e-3);
  EXPECT_NEAR(lambda_closed, 0.127, 5e-4);
  // There the stiffness does not change with the axial load (to first order) while at λ = ½ it
  // changes by about 2 % per newton.
  const PivotGeometry g = ReportStrip(45.0, lambda_closed);
  const double k0 = SmallAngleStiffness(g, 0.0);
  EXPECT_LT(std::abs(SmallAngleStiffness(g, 5.0) - k0) / k0, 2e-3);
  const PivotGeometry mid = ReportStrip(45.0, 0.5);
  const double k0m = SmallAngleStiffness(mid, 0.0);
  EXPECT_GT(std::abs(SmallAngleStiffness(mid, 5.0) - k0m) / k0m, 0.1);
}

TEST(PivotExact, StiffnessByImplicitDifferentiationMatchesFiniteDifferences) {
  const PivotGeometry g = ReportStrip();
  for (const auto& [theta, v, h] :
       {std::tuple{15.0, 10.0, 5.0}, std::tuple{20.0, -60.0, 20.0}, std::tuple{8.0, 20.0, -10.0}}) {
    const PivotResult r = Exact(g, theta, v, h);
    const double dth = 1e-3;  // deg
    const double fd =
        (Exact(g, theta + dth, v, h).c_nm - Exact(g, theta - dth, v, h).c_nm) / (2 * dth * kDeg);
    EXPECT_NEAR(r.dc_dtheta_nm_per_rad, fd, 1e-6 * std::abs(r.c_nm / (theta * kDeg)) + 1e-9);
  }
}

TEST(PivotExact, CoupleIsTheDerivativeOfThePotentialEnergy) {
  // Work–energy check at large deflection, independent of how C is assembled from end forces and
  // moments: with dead loads V, H at the body point, C = d/dθ [U − V·dY − H·dX].
  const PivotGeometry g = ReportStrip();
  for (const auto& [theta, v, h] : {std::tuple{20.0, 10.0, 5.0}, std::tuple{18.0, -60.0, 20.0},
                                    std::tuple{-12.0, 0.0, -15.0}}) {
    auto potential = [&](double th_deg) {
      const PivotResult r = Exact(g, th_deg, v, h);
      return r.strain_energy_j - v * r.dy_m - h * r.dx_m;
    };
    const double dth = 1e-3;  // deg
    const double dpi_dtheta = (potential(theta + dth) - potential(theta - dth)) / (2 * dth * kDeg);
    const PivotResult r = Exact(g, theta, v, h);
    EXPECT_NEAR(r.c_nm, dpi_dtheta, 1e-6 * std::abs(r.c_nm) + 1e-9) << theta << " " << v;
  }
}

TEST(PivotExact, MirrorSymmetry) {
  // Mirroring x → −x maps the pivot onto itself with the strips swapped: θ → −θ, H → −H,
  // dX → −dX, C → −C, while dY and the strip quantities (swapped) stay.
  const PivotGeometry g = ReportStrip(50.0);
  for (const PivotMethod m : {PivotMethod::kExact, PivotMethod::kWittrick}) {
    const PivotResult a = SolvePivot(g, {17 * kDeg, 7.0, 4.0}, m);
    const PivotResult b = SolvePivot(g, {-17 * kDeg, 7.0, -4.0}, m);
    ASSERT_TRUE(a.converged && b.converged);
    EXPECT_NEAR(a.c_nm, -b.c_nm, 1e-9 * std::abs(a.c_nm));
    EXPECT_NEAR(a.dx_m, -b.dx_m, 1e-9 * g.length_m);
    EXPECT_NEAR(a.dy_m, b.dy_m, 1e-9 * g.length_m);
    EXPECT_NEAR(a.f[0], b.f[1], 1e-7 * (1 + std::abs(a.f[0])));
    EXPECT_NEAR(a.mb[0], -b.mb[1], 1e-7 * (1 + std::abs(a.mb[0])));
    EXPECT_NEAR(a.dc_dtheta_nm_per_rad, b.dc_dtheta_nm_per_rad,
                1e-6 * std::abs(a.dc_dtheta_nm_per_rad));
  }
}

TEST(PivotExact, DiscretisationIsConverged) {
  // RK4 error scales as h⁴: 200 steps against 800 steps bounds the error of the default.
  const PivotGeometry g = ReportStrip();
  PivotOptions fine;
  fine.integration_steps = 800;
  for (const auto& [theta, v, h] :
       {std::tuple{20.0, -100.0, 20.0}, std::tuple{20.0, 15.0, -20.0}, std::tuple{5.0, 0.0, 0.0}}) {
    const PivotLoad load{theta * kDeg, v, h};
    const PivotResult a = SolvePivot(g, load, PivotMethod::kExact);
    const PivotResult b = SolvePivot(g, load, PivotMethod::kExact, fine);
    EXPECT_NEAR(a.c_nm / b.c_nm, 1.0, 1e-6);
    EXPECT_NEAR(a.dy_m / b.dy_m, 1.0, 1e-6);
  }
}

TEST(PivotExact, ForcesBalanceTheLoadsAndMomentsMatchTheCouple) {
  // Independent check of the reported strip quantities: at θ = 0 with only V, symmetry gives equal
  // axial forces N = V/(2·cos α) and no bending.
  const PivotGeometry g = ReportStrip(40.0);
  const PivotResult r = Exact(g, 0.0, 12.0, 0.0);
  ASSERT_TRUE(r.valid) << r.reason;
  const double n = 12.0 / (2 * std::cos(g.alpha_rad));
  EXPECT_NEAR(r.axial_n[0], n, 1e-9 * n);
  EXPECT_NEAR(r.axial_n[1], n, 1e-9 * n);
  const double scale = g.length_m * g.length_m / g.BendingStiffness();
  EXPECT_NEAR(r.f[0], n * scale, 1e-9 * n * scale);
  EXPECT_NEAR(r.mb[0], 0.0, 1e-12);
  EXPECT_NEAR(r.c_nm, 0.0, 1e-12);
  // Pure lateral load at θ = 0: one strip in tension, the other in compression, N = ±H/(2·sin α).
  const PivotResult rh = Exact(g, 0.0, 0.0, 8.0);
  EXPECT_NEAR(rh.axial_n[0], 8.0 / (2 * std::sin(g.alpha_rad)), 1e-3);
  EXPECT_NEAR(rh.axial_n[1], -8.0 / (2 * std::sin(g.alpha_rad)), 1e-3);
}

// ---- The two formulations against each other ---------------------------------------------------

TEST(PivotWittrick, AgreesWithExactForSmallRotations) {
  // Both are exact to first order in θ; at 1° the difference is O(θ²) ≈ 3e-4 relative.
  const PivotGeometry g = ReportStrip();
  for (const double v : {-80.0, -20.0, 0.0, 10.0, 18.0}) {
    for (const double h : {-10.0, 0.0, 10.0}) {
      const PivotLoad load{1.0 * kDeg, v, h};
      const PivotResult e = SolvePivot(g, load, PivotMethod::kExact);
      const PivotResult w = SolvePivot(g, load, PivotMethod::kWittrick);
      ASSERT_TRUE(e.converged && w.converged);
      EXPECT_NEAR(w.c_nm / e.c_nm, 1.0, 5e-3) << "V " << v << " H " << h;
      EXPECT_NEAR(w.dc_dtheta_nm_per_rad / e.dc_dtheta_nm_per_rad, 1.0, 5e-3);
    }
  }
}

TEST(PivotAgreement, DefaultFormulationWithin2PercentOfExactUpTo20Degrees) {
  // The acceptance rule, on the report's strip over the stable range (|θ| ≤ 20°, tension up to
  // 15 N — the stability limit is ≈ 23 N —, compression to 100 N, lateral ±20 N), with the
  // Wittrick formulation's error printed beside it (the table of docs/pivot.md).
  const PivotGeometry g = ReportStrip();
  PivotOptions fine;
  fine.integration_steps = 1600;
  std::printf(
      "| theta deg | V N | H N | C exact N*m | C wittrick N*m | wittrick err %% | "
      "default err %% | iterations exact/wittrick |\n|---|---|---|---|---|---|---|---|\n");
  double worst_default = 0.0, worst_wittrick = 0.0;
  int iterations_max = 0, valid_cases = 0;
  for (const double theta : {-20.0, 2.0, 5.0, 10.0, 15.0, 20.0}) {
    for (const double v : {-100.0, -60.0, -30.0, 0.0, 10.0, 15.0}) {
      for (const double h : {-20.0, 0.0, 20.0}) {
        const PivotLoad load{theta * kDeg, v, h};
        const PivotResult ref = SolvePivot(g, load, PivotMethod::kExact, fine);
        if (!ref.valid) continue;
        ++valid_cases;
        const PivotResult def = SolvePivot(g, load, kDefaultPivotMethod);
        const PivotResult wit = SolvePivot(g, load, PivotMethod::kWittrick);
        const double err_def = 100 * (def.c_nm - ref.c_nm) / ref.c_nm;
        const double err_wit = 100 * (wit.c_nm - ref.c_nm) / ref.c_nm;
        worst_default = std::max(worst_default, std::abs(err_def));
        worst_wittrick = std::max(worst_wittrick, std::abs(err_wit));
        iterations_max = std::max(iterations_max, def.iterations);
        std::printf("| %g | %g | %g | %.5g | %.5g | %+.2f | %+.1e | %d/%d |\n", theta, v, h,
                    ref.c_nm, wit.c_nm, err_wit, err_def, def.iterations, wit.iterations);
        EXPECT_TRUE(def.valid) << def.reason;
        EXPECT_LT(std::abs(err_def), 2.0) << theta << " " << v << " " << h;
      }
    }
  }
  std::printf(
      "valid cases %d, worst |error| default %.2e %%, wittrick %.2f %%, max iterations %d\n",
      valid_cases, worst_default, worst_wittrick, iterations_max);
  EXPECT_GT(valid_cases, 80);
  EXPECT_LE(iterations_max, 40);  // "converging in tens of iterations"
}

// ---- Validity ----------------------------------------------------------------------------------

TEST(PivotValidity, ReportCaseThirtyDegreesHundredNewtonsIsInvalid) {
  const PivotGeometry g = ReportStrip();
  for (const PivotMethod m : {PivotMethod::kExact, PivotMethod::kWittrick}) {
    const PivotResult r = SolvePivot(g, {30 * kDeg, 100.0, 100.0}, m);
    EXPECT_FALSE(r.valid);
    EXPECT_NE(r.reason.find("unstable"), std::string::npos) << r.reason;
    EXPECT_LT(r.dc_dtheta_nm_per_rad, 0.0);
  }
}

TEST(PivotValidity, TensionStabilityLimitNearFirstOrderPrediction) {
  // First order: K = 0 at V = 12·EI·cos α / L² (≈ 23.9 N here); the exact limit lies within a few
  // per cent of it (second-order terms in V).
  const PivotGeometry g = ReportStrip();
  const double v_crit =
      12 * g.BendingStiffness() * std::cos(g.alpha_rad) / (g.length_m * g.length_m);
  EXPECT_TRUE(Exact(g, 0.5, 0.9 * v_crit, 0.0).valid);
  const PivotResult beyond = Exact(g, 0.5, 1.1 * v_crit, 0.0);
  EXPECT_FALSE(beyond.valid);
  EXPECT_NE(beyond.reason.find("unstable"), std::string::npos) << beyond.reason;
}

TEST(PivotValidity, BucklingYieldAndNonConvergenceAreReported) {
  const PivotGeometry g = ReportStrip();
  // Compression per strip V/(2 cos α) = 1.1 × the clamped–clamped Euler load.
  const double v = -1.1 * g.EulerLoad() * 2 * std::cos(g.alpha_rad);
  const PivotResult buckled = Exact(g, 2.0, v, 0.0);
  EXPECT_FALSE(buckled.valid);
  EXPECT_NE(buckled.reason.find("buckled"), std::string::npos) << buckled.reason;

  // Yield: pure bending stress at θ is 6·M/(b·t²) with M ≈ EI·θ/L = E·t·θ/(2L) · (b t²/6).
  PivotGeometry weak = g;
  const double theta = 10 * kDeg;
  const double sigma_bending = g.e_pa * g.thickness_m * theta / (2 * g.length_m);  // ≈ 89 MPa
  weak.yield_pa = 0.8 * sigma_bending;
  const PivotResult yielded = SolvePivot(weak, {theta, 0.0, 0.0}, PivotMethod::kExact);
  EXPECT_FALSE(yielded.valid);
  EXPECT_NE(yielded.reason.find("yield"), std::string::npos) << yielded.reason;
  weak.yield_pa = 1.3 * sigma_bending;
  EXPECT_TRUE(SolvePivot(weak, {theta, 0.0, 0.0}, PivotMethod::kExact).valid);

  // Far beyond buckling the solver finds no equilibrium; the reason still names the buckling.
  const PivotResult crushed = Exact(g, -45.0, -1000.0, 0.0);
  EXPECT_FALSE(crushed.valid);
  EXPECT_NE(crushed.reason.find("buckled"), std::string::npos) << crushed.reason;
  EXPECT_TRUE(std::isnan(crushed.c_nm));

  PivotOptions starved;
  starved.max_iterations = 1;
  const PivotResult r = SolvePivot(g, {20 * kDeg, 10.0, 5.0}, PivotMethod::kExact, starved);
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.reason.find("no convergence"), std::string::npos) << r.reason;
}

TEST(PivotValidity, BadInputsThrow) {
  PivotGeometry g = ReportStrip();
  EXPECT_THROW((void)SolvePivot(g, {std::nan(""), 0, 0}, PivotMethod::kExact),
               std::invalid_argument);
  EXPECT_THROW((void)SolvePivot(g, {0.1, INFINITY, 0}, PivotMethod::kExact), std::invalid_argument);
  g.thickness_m = -1e-3;
  EXPECT_THROW((void)SolvePivot(g, {0.1, 0, 0}, PivotMethod::kExact), std::invalid_argument);
  g = ReportStrip(90.0);
  EXPECT_THROW((void)SolvePivot(g, {0.1, 0, 0}, PivotMethod::kExact), std::invalid_argument);
}

}  // namespace
}  // namespace ftstack::sim::pivot
