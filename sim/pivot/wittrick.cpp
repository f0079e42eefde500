// Wittrick-type pivot: beam-column strips (small slopes, exact axial-load effect) + second-order
// compatibility.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "sim/pivot/internal.hpp"
#include "sim/pivot/newton.hpp"
#include "sim/pivot/pivot.hpp"

namespace ftstack::sim::pivot {

namespace {

// The clamped-at-zero solutions of w'''' = p·w'': w = a·C(s) + b·S(s) with C(0) = C'(0) = S(0) =
// S'(0) = 0, C'' (0) = 1, S'''(0) = 1. For p > 0 (tension) hyperbolic, p < 0 trigonometric, series
// near p = 0 (where the closed forms cancel).
struct Basis {
  double c, dc, ddc, s, ds, dds;
};

Basis EvalBasis(double p, double x) {
  Basis b{};
  if (std::abs(p) < 1e-3) {
    const double x2 = x * x, x3 = x2 * x, x4 = x2 * x2, x5 = x4 * x, x6 = x3 * x3, x7 = x6 * x;
    const double p2 = p * p;
    b.c = x2 / 2 + p * x4 / 24 + p2 * x6 / 720;
    b.dc = x + p * x3 / 6 + p2 * x5 / 120;
    b.ddc = 1 + p * x2 / 2 + p2 * x4 / 24;
    b.s = x3 / 6 + p * x5 / 120 + p2 * x7 / 5040;
    b.ds = b.c;
    b.dds = b.dc;
  } else if (p > 0) {
    const double k = std::sqrt(p), kx = k * x;
    const double ch = std::cosh(kx), sh = std::sinh(kx);
    b.c = (ch - 1) / p;
    b.dc = sh / k;
    b.ddc = ch;
    b.s = (sh - kx) / (p * k);
    b.ds = b.c;
    b.dds = b.dc;
  } else {
    const double k = std::sqrt(-p), kx = k * x;
    const double co = std::cos(kx), si = std::sin(kx);
    b.c = (1 - co) / (-p);
    b.dc = si / k;
    b.ddc = co;
    b.s = (kx - si) / (-p * k);
    b.ds = b.c;
    b.dds = b.dc;
  }
  return b;
}

// Gauss–Legendre nodes and weights on [0, 1], computed once by Newton on P_n.
struct GaussLegendre {
  static constexpr int kN = 24;
  std::array<double, kN> x{}, w{};
  GaussLegendre() {
    for (int i = 0; i < kN; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (kN + 0.5));
      double dp = 1.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= kN; ++k) {
          const double pk = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = pk;
        }
        dp = kN * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x[i] = 0.5 * (1.0 - z);
      w[i] = 1.0 / ((1.0 - z * z) * dp * dp);  // 2/((1−z²)P'²) scaled by ½ for [0, 1]
    }
  }
};

const GaussLegendre& Quadrature() {
  static const GaussLegendre q;
  return q;
}

}  // namespace

BeamColumnEnd SolveBeamColumn(double p, double w1, double theta, bool with_max_moment) {
  BeamColumnEnd out;
  const Basis e = EvalBasis(p, 1.0);
  const double det = e.c * e.ds - e.s * e.dc;
  if (!std::isfinite(det) || std::abs(det) < 1e-12) {
    out.singular = true;
    return out;
  }
  const double a = (w1 * e.ds - e.s * theta) / det;
  const double b = (e.c * theta - e.dc * w1) / det;
  out.m_b = a * e.ddc + b * e.dds;
  // w''' = −q + p·w' and w'(0) = 0, S'''(0) = 1, C'''(0) = 0  ⇒  q = −b.
  out.q = -b;
  const auto& gl = Quadrature();
  double integral = 0.0;
  for (int i = 0; i < GaussLegendre::kN; ++i) {
    const Basis bi = EvalBasis(p, gl.x[i]);
    const double slope = a * bi.dc + b * bi.ds;
    integral += gl.w[i] * slope * slope;
  }
  out.shortening = 0.5 * integral;
  constexpr int kSamples = 64;
  for (int i = 0; with_max_moment && i <= kSamples; ++i) {
    const Basis bi = EvalBasis(p, static_cast<double>(i) / kSamples);
    out.max_abs_m = std::max(out.max_abs_m, std::abs(a * bi.ddc + b * bi.dds));
  }
  return out;
}

namespace detail {

namespace {

// Unknowns z = [dX, dY, p_1, p_2] (units of L and EI/L²). For strip i, the body end moves by
// Δ = d + (R(θ) − I)ρ_i; its components along the strip (u) and across it (w) are the end
// conditions: w and θ drive the beam-column, and inextensibility asks u = −½∫w'². Equilibrium of
// the body: Σ (p_i e_i + q_i n_i) = (h, v), forces written along the undeformed strip axes.
struct WittrickSystem : DimensionlessPivot {
  bool Strip(const Eigen::VectorXd& z, double th, int i, BeamColumnEnd& bc,
             bool with_max_moment = false) const {
    const Eigen::Vector2d d(z[0], z[1]);
    const Eigen::Vector2d delta = d + (Rot(th) - Eigen::Matrix2d::Identity()) * strips[i].rho;
    bc = SolveBeamColumn(z[2 + i], delta.dot(strips[i].n), th, with_max_moment);
    return !bc.singular;
  }

  bool Residual(const Eigen::VectorXd& z, double th, double hh, double vv,
                Eigen::VectorXd& r) const {
    r.resize(4);
    Eigen::Vector2d force = Eigen::Vector2d::Zero();
    for (int i = 0; i < 2; ++i) {
      BeamColumnEnd bc;
      if (!Strip(z, th, i, bc)) return false;
      const Eigen::Vector2d d(z[0], z[1]);
      const Eigen::Vector2d delta = d + (Rot(th) - Eigen::Matrix2d::Identity()) * strips[i].rho;
      r[i] = delta.dot(strips[i].e) + bc.shortening;
      force += z[2 + i] * strips[i].e + bc.q * strips[i].n;
    }
    r[2] = force.x() - hh;
    r[3] = force.y() - vv;
    return true;
  }

  bool Eval(const Eigen::VectorXd& z, double tau, Eigen::VectorXd& r, Eigen::MatrixXd* j) const {
    const double th = tau * theta, hh = tau * h, vv = tau * v;
    if (!Residual(z, th, hh, vv, r)) return false;
    if (j == nullptr) return true;
    j->resize(4, 4);
    Eigen::VectorXd rp(4), rm(4);
    for (int k = 0; k < 4; ++k) {
      const double step = 1e-7 * (1.0 + std::abs(z[k]));
      Eigen::VectorXd zp = z, zm = z;
      zp[k] += step;
      zm[k] -= step;
      if (!Residual(zp, th, hh, vv, rp) || !Residual(zm, th, hh, vv, rm)) return false;
      j->col(k) = (rp - rm) / (2.0 * step);
    }
    return true;
  }

  /// Dimensionless couple c = Σ m_B,i + (R(θ)ρ_i) × (p_i e_i + q_i n_i).
  double Couple(const Eigen::VectorXd& z, double th) const {
    double c = 0.0;
    for (int i = 0; i < 2; ++i) {
      BeamColumnEnd bc;
      if (!Strip(z, th, i, bc)) return std::nan("");
      const Eigen::Vector2d f = z[2 + i] * strips[i].e + bc.q * strips[i].n;
      c += bc.m_b + Cross(Rot(th) * strips[i].rho, f);
    }
    return c;
  }
};

}  // namespace

PivotResult SolveWittrick(const PivotGeometry& g, const PivotLoad& load,
                          const PivotOptions& options) {
  const double ei = g.BendingStiffness(), l = g.length_m;
  WittrickSystem sys;
  static_cast<DimensionlessPivot&>(sys) = MakeDimensionless(g, load);
  const SystemFn fn = [&sys](const Eigen::VectorXd& x, double tau, Eigen::VectorXd& r,
                             Eigen::MatrixXd* j) { return sys.Eval(x, tau, r, j); };
  Eigen::VectorXd z = Eigen::VectorXd::Zero(4);
  const NewtonOutcome out = ContinuationSolve(fn, z, options.max_iterations, options.tolerance);
  PivotResult res;
  res.iterations = out.iterations;
  res.converged = out.converged;
  if (!out.converged) return res;

  const StressWeights w = MakeStressWeights(g);
  for (int i = 0; i < 2; ++i) {
    BeamColumnEnd bc;
    sys.Strip(z, sys.theta, i, bc, true);
    res.f[i] = z[2 + i];
    res.mb[i] = bc.m_b;
    res.axial_n[i] = z[2 + i] * ei / (l * l);
    res.moment_b_nm[i] = bc.m_b * ei / l;
    res.max_stress_pa = std::max(
        res.max_stress_pa, bc.max_abs_m * w.moment_weight + std::abs(z[2 + i]) * w.axial_weight);
    res.max_compression_n = std::max(res.max_compression_n, -res.axial_n[i]);
    if (options.want_shape) {
      const int n = options.integration_steps;
      const Eigen::Vector2d d(z[0], z[1]);
      const Eigen::Vector2d delta =
          d + (Rot(sys.theta) - Eigen::Matrix2d::Identity()) * sys.strips[i].rho;
      const double w1 = delta.dot(sys.strips[i].n);
      // Reconstruct w(s) from the end conditions (same solve as SolveBeamColumn).
      const Basis e = EvalBasis(z[2 + i], 1.0);
      const double det = e.c * e.ds - e.s * e.dc;
      const double a = (w1 * e.ds - e.s * sys.theta) / det;
      const double b = (e.c * sys.theta - e.dc * w1) / det;
      const double u1 = delta.dot(sys.strips[i].e);
      for (int k = 0; k <= n; ++k) {
        const double s = static_cast<double>(k) / n;
        const Basis bs = EvalBasis(z[2 + i], s);
        const double wk = a * bs.c + b * bs.s;
        // Axial position: inextensible, so the approach grows with ½∫w'²; linear in s is enough
        // for a picture (the end matches u1 exactly).
        const Eigen::Vector2d p =
            sys.strips[i].base + (s + s * u1) * sys.strips[i].e + wk * sys.strips[i].n;
        res.shape_m[i].push_back(p * l);
      }
    }
  }
  const double c = sys.Couple(z, sys.theta);
  // Stiffness by central differences in θ, each side re-solved by Newton from this solution.
  const double dth = 1e-5;
  double c_side[2] = {0.0, 0.0};
  bool ok = true;
  for (int side = 0; side < 2; ++side) {
    WittrickSystem s2 = sys;
    s2.theta = sys.theta + (side == 0 ? dth : -dth);
    const SystemFn f2 = [&s2](const Eigen::VectorXd& x, double tau, Eigen::VectorXd& r,
                              Eigen::MatrixXd* j) { return s2.Eval(x, tau, r, j); };
    Eigen::VectorXd z2 = z;
    const NewtonOutcome o2 = NewtonSolve(f2, z2, 1.0, 20, options.tolerance);
    ok = ok && o2.converged;
    c_side[side] = s2.Couple(z2, s2.theta);
  }
  res.c_nm = c * ei / l;
  res.dc_dtheta_nm_per_rad = ok ? (c_side[0] - c_side[1]) / (2.0 * dth) * ei / l : std::nan("");
  res.dx_m = z[0] * l;
  res.dy_m = z[1] * l;
  return res;
}

}  // namespace detail
}  // namespace ftstack::sim::pivot
