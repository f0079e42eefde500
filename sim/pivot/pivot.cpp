// Crossed-strip flexure pivot: input checks, validity rules and the choice of formulation.
#include "sim/pivot/pivot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sim/pivot/internal.hpp"

namespace ftstack::sim::pivot {

double PivotGeometry::BendingStiffness() const {
  return e_pa * width_m * thickness_m * thickness_m * thickness_m / 12.0;
}

double PivotGeometry::EulerLoad() const {
  return 4.0 * std::numbers::pi * std::numbers::pi * BendingStiffness() / (length_m * length_m);
}

const char* ToString(PivotMethod m) { return m == PivotMethod::kExact ? "exact" : "wittrick"; }

namespace {
void RequirePositive(double v, const char* name) {
  if (!std::isfinite(v) || v <= 0.0) {
    throw std::invalid_argument(std::string(name) + " must be a finite number > 0, got " +
                                std::to_string(v));
  }
}
void RequireFinite(double v, const char* name) {
  if (!std::isfinite(v)) throw std::invalid_argument(std::string(name) + " must be finite");
}
}  // namespace

void ValidateInputs(const PivotGeometry& g, const PivotLoad& load) {
  RequirePositive(g.e_pa, "E");
  RequirePositive(g.length_m, "L");
  RequirePositive(g.width_m, "b");
  RequirePositive(g.thickness_m, "t");
  RequirePositive(g.yield_pa, "yield");
  RequireFinite(g.alpha_rad, "alpha");
  if (g.alpha_rad <= 0.0 || g.alpha_rad >= std::numbers::pi / 2) {
    throw std::invalid_argument("alpha must lie strictly between 0 and 90 degrees");
  }
  RequireFinite(g.crossing_fraction, "lambda");
  if (g.crossing_fraction <= 0.0 || g.crossing_fraction >= 1.0) {
    throw std::invalid_argument("lambda (crossing fraction) must lie strictly between 0 and 1");
  }
  RequireFinite(load.theta_rad, "theta");
  if (std::abs(load.theta_rad) >= std::numbers::pi / 2) {
    throw std::invalid_argument("|theta| must be below 90 degrees");
  }
  RequireFinite(load.v_n, "V");
  RequireFinite(load.h_n, "H");
}

PivotResult SolvePivot(const PivotGeometry& g, const PivotLoad& load, PivotMethod method,
                       const PivotOptions& options) {
  ValidateInputs(g, load);
  if (options.integration_steps < 8 || options.max_iterations < 1 || !(options.tolerance > 0.0)) {
    throw std::invalid_argument("pivot options: steps >= 8, iterations >= 1, tolerance > 0");
  }
  PivotResult r = method == PivotMethod::kExact ? detail::SolveExact(g, load, options)
                                                : detail::SolveWittrick(g, load, options);
  r.method = method;
  detail::Judge(g, load, r);
  return r;
}

namespace detail {

std::array<StripFrame, 2> StripFrames(const PivotGeometry& g) {
  std::array<StripFrame, 2> s;
  const double sa = std::sin(g.alpha_rad), ca = std::cos(g.alpha_rad);
  for (int i = 0; i < 2; ++i) {
    const double sign = i == 0 ? 1.0 : -1.0;
    s[i].e = Eigen::Vector2d(sign * sa, ca);
    s[i].n = Eigen::Vector2d(-s[i].e.y(), s[i].e.x());
    s[i].base = -g.crossing_fraction * s[i].e;
    s[i].rho = (1.0 - g.crossing_fraction) * s[i].e;
    s[i].phi0 = std::atan2(s[i].e.y(), s[i].e.x());
  }
  return s;
}

DimensionlessPivot MakeDimensionless(const PivotGeometry& g, const PivotLoad& load) {
  const double force_unit = g.BendingStiffness() / (g.length_m * g.length_m);
  DimensionlessPivot d;
  d.strips = StripFrames(g);
  d.theta = load.theta_rad;
  d.h = load.h_n / force_unit;
  d.v = load.v_n / force_unit;
  return d;
}

Eigen::Matrix2d Rot(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix2d m;
  m << c, -s, s, c;
  return m;
}

Eigen::Matrix2d RotDerivative(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix2d m;
  m << -s, -c, c, -s;
  return m;
}

StressWeights MakeStressWeights(const PivotGeometry& g) {
  const double ei = g.BendingStiffness(), l = g.length_m;
  const double b = g.width_m, t = g.thickness_m;
  return {ei / l * 6.0 / (b * t * t), ei / (l * l) / (b * t)};
}

void Judge(const PivotGeometry& g, const PivotLoad& load, PivotResult& r) {
  std::string reason;
  auto add = [&reason](const std::string& s) { reason += (reason.empty() ? "" : "; ") + s; };
  char buf[256];
  if (!r.converged) {
    std::snprintf(buf, sizeof buf, "no convergence after %d Newton iterations", r.iterations);
    add(buf);
    // Say why where statics of the straight strips already does: N1·e1 + N2·e2 = (H, V).
    const double sa = std::sin(g.alpha_rad), ca = std::cos(g.alpha_rad);
    const double n1 = 0.5 * (load.v_n / ca + load.h_n / sa);
    const double n2 = 0.5 * (load.v_n / ca - load.h_n / sa);
    const double compression = std::max(-n1, -n2);
    if (compression > g.EulerLoad()) {
      std::snprintf(buf, sizeof buf,
                    "buckled: the loads put %.4g N of compression in a straight strip, beyond "
                    "the clamped-clamped Euler load 4*pi^2*EI/L^2 = %.4g N",
                    compression, g.EulerLoad());
      add(buf);
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    r.c_nm = r.dx_m = r.dy_m = r.dc_dtheta_nm_per_rad = r.max_stress_pa = nan;
    r.max_compression_n = nan;
    r.f = r.mb = r.axial_n = r.moment_b_nm = {nan, nan};
  } else {
    if (!(r.dc_dtheta_nm_per_rad > 0.0)) {
      std::snprintf(buf, sizeof buf,
                    "unstable: rotational stiffness dC/dtheta = %.4g N*m/rad <= 0 (the loads "
                    "overcome the strips' bending stiffness)",
                    r.dc_dtheta_nm_per_rad);
      add(buf);
    }
    if (r.max_compression_n > g.EulerLoad()) {
      std::snprintf(buf, sizeof buf,
                    "buckled: strip compression %.4g N exceeds the clamped-clamped Euler load "
                    "4*pi^2*EI/L^2 = %.4g N",
                    r.max_compression_n, g.EulerLoad());
      add(buf);
    }
    if (r.max_stress_pa > g.yield_pa) {
      std::snprintf(buf, sizeof buf, "yield exceeded: max stress %.4g MPa > yield %.4g MPa",
                    r.max_stress_pa / 1e6, g.yield_pa / 1e6);
      add(buf);
    }
  }
  r.valid = reason.empty();
  r.reason = reason;
}

}  // namespace detail
}  // namespace ftstack::sim::pivot
