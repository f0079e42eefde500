// Damped Newton solver with load continuation, shared by the two pivot formulations.
#include "sim/pivot/newton.hpp"

#include <algorithm>
#include <cmath>

namespace ftstack::sim::pivot::detail {

namespace {
bool AllFinite(const Eigen::VectorXd& v) { return v.allFinite(); }
}  // namespace

NewtonOutcome NewtonSolve(const SystemFn& f, Eigen::VectorXd& u, double tau, int max_iterations,
                          double tolerance) {
  NewtonOutcome out;
  const auto n = u.size();
  Eigen::VectorXd r(n);
  Eigen::MatrixXd j(n, n);
  if (!f(u, tau, r, &j) || !AllFinite(r)) return out;
  for (;;) {
    if (r.lpNorm<Eigen::Infinity>() < tolerance) {
      out.converged = true;
      return out;
    }
    if (out.iterations >= max_iterations) return out;
    ++out.iterations;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
    if (lu.rank() < n) return out;
    const Eigen::VectorXd step = lu.solve(-r);
    if (!AllFinite(step)) return out;
    const double merit0 = 0.5 * r.squaredNorm();
    // Armijo: the directional derivative of ½|r|² along a Newton step is −|r|².
    double lambda = 1.0;
    bool accepted = false;
    // Trial points are evaluated with their Jacobian: the accepted one (usually the full step)
    // is then the next iterate without another evaluation.
    Eigen::VectorXd u_try(n), r_try(n);
    Eigen::MatrixXd j_try(n, n);
    for (int halvings = 0; halvings < 30; ++halvings, lambda *= 0.5) {
      u_try = u + lambda * step;
      if (!f(u_try, tau, r_try, &j_try) || !AllFinite(r_try)) continue;
      if (0.5 * r_try.squaredNorm() <= merit0 * (1.0 - 2e-4 * lambda)) {
        accepted = true;
        break;
      }
    }
    if (!accepted) return out;
    u.swap(u_try);
    r.swap(r_try);
    j.swap(j_try);
  }
}

NewtonOutcome ContinuationSolve(const SystemFn& f, Eigen::VectorXd& u, int max_iterations,
                                double tolerance) {
  NewtonOutcome total;
  double tau = 0.0, dtau = 1.0, last_dtau = 0.0;
  Eigen::VectorXd u_prev = u;
  constexpr int kPerStep = 25;
  while (tau < 1.0) {
    const double tau_try = std::min(1.0, tau + dtau);
    Eigen::VectorXd u_try = u;
    if (last_dtau > 0.0) u_try += (u - u_prev) * ((tau_try - tau) / last_dtau);
    const int budget = std::min(kPerStep, max_iterations - total.iterations);
    if (budget <= 0) return total;
    const NewtonOutcome step = NewtonSolve(f, u_try, tau_try, budget, tolerance);
    total.iterations += step.iterations;
    if (step.converged) {
      u_prev = u;
      u = u_try;
      last_dtau = tau_try - tau;
      tau = tau_try;
      if (step.iterations <= 6) dtau *= 2.0;
    } else {
      dtau *= 0.5;
      if (dtau < 1e-5) return total;
    }
  }
  total.converged = true;
  return total;
}

}  // namespace ftstack::sim::pivot::detail
