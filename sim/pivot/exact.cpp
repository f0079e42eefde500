// Exact large-deflection pivot: inextensible elastica of each strip, shooting + Newton on all ends.
#include <algorithm>
#include <array>
#include <cmath>

#include "sim/pivot/internal.hpp"
#include "sim/pivot/newton.hpp"
#include "sim/pivot/pivot.hpp"

namespace ftstack::sim::pivot {

namespace {

// State: phi, m, x, y, then the 4×3 sensitivity d(phi, m, x, y)/d(m0, fx, fy), row-major, then
// the bending energy ½∫m² ds.
using State = std::array<double, 17>;

void Derivative(const State& y, double fx, double fy, State& dy) {
  const double c = std::cos(y[0]), s = std::sin(y[0]);
  dy[0] = y[1];
  dy[1] = fx * s - fy * c;
  dy[2] = c;
  dy[3] = s;
  const double dm_dphi = fx * c + fy * s;
  const double b[3] = {0.0, s, -c};
  for (int k = 0; k < 3; ++k) {
    const double s_phi = y[4 + k], s_m = y[7 + k];
    dy[4 + k] = s_m;
    dy[7 + k] = dm_dphi * s_phi + b[k];
    dy[10 + k] = -s * s_phi;
    dy[13 + k] = c * s_phi;
  }
  dy[16] = 0.5 * y[1] * y[1];
}

}  // namespace

ElasticaEnd IntegrateElastica(double phi0, double m0, double x0, double y0, double fx, double fy,
                              int steps, double m_weight, double n_weight,
                              std::vector<Eigen::Vector2d>* shape) {
  State y{};
  y[0] = phi0;
  y[1] = m0;
  y[2] = x0;
  y[3] = y0;
  y[7] = 1.0;  // d m(0) / d m0
  ElasticaEnd end;
  auto track = [&](const State& st) {
    const double n = fx * std::cos(st[0]) + fy * std::sin(st[0]);
    end.max_abs_m = std::max(end.max_abs_m, std::abs(st[1]));
    end.max_abs_n = std::max(end.max_abs_n, std::abs(n));
    end.max_stress_index =
        std::max(end.max_stress_index, std::abs(st[1]) * m_weight + std::abs(n) * n_weight);
    end.max_compression = std::max(end.max_compression, -n);
    if (shape != nullptr) shape->emplace_back(st[2], st[3]);
  };
  if (shape != nullptr) {
    shape->clear();
    shape->reserve(static_cast<size_t>(steps) + 1);
  }
  track(y);
  const double h = 1.0 / steps;
  State k1, k2, k3, k4, tmp;
  for (int i = 0; i < steps; ++i) {
    Derivative(y, fx, fy, k1);
    for (size_t j = 0; j < y.size(); ++j) tmp[j] = y[j] + 0.5 * h * k1[j];
    Derivative(tmp, fx, fy, k2);
    for (size_t j = 0; j < y.size(); ++j) tmp[j] = y[j] + 0.5 * h * k2[j];
    Derivative(tmp, fx, fy, k3);
    for (size_t j = 0; j < y.size(); ++j) tmp[j] = y[j] + h * k3[j];
    Derivative(tmp, fx, fy, k4);
    for (size_t j = 0; j < y.size(); ++j)
      y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
    track(y);
  }
  end.phi = y[0];
  end.m = y[1];
  end.x = y[2];
  end.y = y[3];
  end.energy = y[16];
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < 3; ++k) end.sensitivity(r, k) = y[4 + 3 * r + k];
  }
  return end;
}

namespace detail {

namespace {

// Unknowns u = [dX, dY, m0_1, fx_1, fy_1, m0_2, fx_2, fy_2] (units of L, EI/L, EI/L²): the body
// point's displacement, then for each strip its base moment and the constant force it receives
// from the moving body. Residuals: for each strip its end angle and end position against the
// clamp on the rotated, displaced body (3 each), then body force balance f_1 + f_2 = (h, v).
struct ExactSystem : DimensionlessPivot {
  int steps = 200;
  StressWeights w;

  std::array<ElasticaEnd, 2> Integrate(const Eigen::VectorXd& u, std::array<double, 2> phi0,
                                       std::array<std::vector<Eigen::Vector2d>*, 2> shapes = {
                                           nullptr, nullptr}) const {
    std::array<ElasticaEnd, 2> ends;
    for (int i = 0; i < 2; ++i) {
      const int o = 2 + 3 * i;
      ends[i] = IntegrateElastica(phi0[i], u[o], strips[i].base.x(), strips[i].base.y(), u[o + 1],
                                  u[o + 2], steps, w.moment_weight, w.axial_weight, shapes[i]);
    }
    return ends;
  }

  bool Eval(const Eigen::VectorXd& u, double tau, Eigen::VectorXd& r, Eigen::MatrixXd* j) const {
    const double th = tau * theta;
    const Eigen::Matrix2d rot = Rot(th);
    const auto ends = Integrate(u, {strips[0].phi0, strips[1].phi0});
    r.resize(8);
    if (j != nullptr) j->setZero(8, 8);
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector2d target = Eigen::Vector2d(u[0], u[1]) + rot * strips[i].rho;
      const int row = 3 * i, col = 2 + 3 * i;
      r[row] = ends[i].phi - (strips[i].phi0 + th);
      r[row + 1] = ends[i].x - target.x();
      r[row + 2] = ends[i].y - target.y();
      if (j != nullptr) {
        for (int k = 0; k < 3; ++k) {
          (*j)(row, col + k) = ends[i].sensitivity(0, k);
          (*j)(row + 1, col + k) = ends[i].sensitivity(2, k);
          (*j)(row + 2, col + k) = ends[i].sensitivity(3, k);
        }
        (*j)(row + 1, 0) = -1.0;
        (*j)(row + 2, 1) = -1.0;
      }
    }
    r[6] = u[3] + u[6] - tau * h;
    r[7] = u[4] + u[7] - tau * v;
    if (j != nullptr) {
      (*j)(6, 3) = (*j)(6, 6) = 1.0;
      (*j)(7, 4) = (*j)(7, 7) = 1.0;
    }
    return true;
  }
};

}  // namespace

PivotResult SolveExact(const PivotGeometry& g, const PivotLoad& load, const PivotOptions& options) {
  const double ei = g.BendingStiffness(), l = g.length_m;
  ExactSystem sys;
  static_cast<DimensionlessPivot&>(sys) = MakeDimensionless(g, load);
  sys.steps = options.integration_steps;
  sys.w = MakeStressWeights(g);

  Eigen::VectorXd u = Eigen::VectorXd::Zero(8);  // straight, unloaded strips solve tau = 0
  const SystemFn fn = [&sys](const Eigen::VectorXd& x, double tau, Eigen::VectorXd& r,
                             Eigen::MatrixXd* j) { return sys.Eval(x, tau, r, j); };
  const NewtonOutcome out = ContinuationSolve(fn, u, options.max_iterations, options.tolerance);

  PivotResult res;
  res.iterations = out.iterations;
  res.converged = out.converged;
  if (!out.converged) return res;

  std::array<std::vector<Eigen::Vector2d>, 2> shapes;
  std::array<std::vector<Eigen::Vector2d>*, 2> shape_ptrs = {nullptr, nullptr};
  if (options.want_shape) shape_ptrs = {&shapes[0], &shapes[1]};
  const auto ends = sys.Integrate(u, {sys.strips[0].phi0, sys.strips[1].phi0}, shape_ptrs);

  // Couple about the body point: c = Σ m_B,i + (R(θ)ρ_i) × f_i; and its total derivative in θ by
  // implicit differentiation of the converged system, dc/dθ = ∂c/∂θ − ∂c/∂u · J⁻¹ ∂r/∂θ.
  const Eigen::Matrix2d rot = Rot(sys.theta), drot = RotDerivative(sys.theta);
  double c = 0.0, dc_dtheta_partial = 0.0;
  Eigen::RowVectorXd dc_du = Eigen::RowVectorXd::Zero(8);
  Eigen::VectorXd dr_dtheta = Eigen::VectorXd::Zero(8);
  for (int i = 0; i < 2; ++i) {
    const int o = 2 + 3 * i;
    const Eigen::Vector2d f(u[o + 1], u[o + 2]);
    const Eigen::Vector2d arm = rot * sys.strips[i].rho, darm = drot * sys.strips[i].rho;
    c += ends[i].m + Cross(arm, f);
    dc_dtheta_partial += Cross(darm, f);
    for (int k = 0; k < 3; ++k) dc_du[o + k] += ends[i].sensitivity(1, k);
    dc_du[o + 1] += -arm.y();
    dc_du[o + 2] += arm.x();
    dr_dtheta[3 * i] = -1.0;
    dr_dtheta[3 * i + 1] = -darm.x();
    dr_dtheta[3 * i + 2] = -darm.y();

    const Eigen::Vector2d tangent(std::cos(ends[i].phi), std::sin(ends[i].phi));
    const double n_axial = f.dot(tangent);
    res.f[i] = n_axial;
    res.mb[i] = ends[i].m;
    res.axial_n[i] = n_axial * ei / (l * l);
    res.moment_b_nm[i] = ends[i].m * ei / l;
    res.max_stress_pa = std::max(res.max_stress_pa, ends[i].max_stress_index);
    res.max_compression_n = std::max(res.max_compression_n, ends[i].max_compression * ei / (l * l));
    res.strain_energy_j += ends[i].energy * ei / l;
    if (options.want_shape) {
      for (auto& p : shapes[i]) p *= l;
      res.shape_m[i] = std::move(shapes[i]);
    }
  }
  Eigen::VectorXd r(8);
  Eigen::MatrixXd j(8, 8);
  sys.Eval(u, 1.0, r, &j);
  const Eigen::VectorXd du_dtheta = Eigen::FullPivLU<Eigen::MatrixXd>(j).solve(-dr_dtheta);
  const double dc_dtheta = dc_dtheta_partial + dc_du.dot(du_dtheta);

  res.c_nm = c * ei / l;
  res.dc_dtheta_nm_per_rad = dc_dtheta * ei / l;
  res.dx_m = u[0] * l;
  res.dy_m = u[1] * l;
  return res;
}

}  // namespace detail
}  // namespace ftstack::sim::pivot
