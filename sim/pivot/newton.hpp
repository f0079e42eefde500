// Damped Newton solver with load continuation, shared by the two pivot formulations (internal).
#pragma once

#include <Eigen/Dense>
#include <functional>

namespace ftstack::sim::pivot::detail {

/// Residual and Jacobian of a square system at parameter tau (the continuation parameter, 0 … 1).
/// Returns false where the residual cannot be evaluated (e.g. a singular beam-column).
using SystemFn = std::function<bool(const Eigen::VectorXd& u, double tau, Eigen::VectorXd& r,
                                    Eigen::MatrixXd* j)>;

struct NewtonOutcome {
  bool converged = false;
  int iterations = 0;
};

/// Newton with an Armijo backtracking line search on ½|r|², at fixed tau, from u (updated in
/// place).
NewtonOutcome NewtonSolve(const SystemFn& f, Eigen::VectorXd& u, double tau, int max_iterations,
                          double tolerance);

/// Continuation from tau = 0 (where u must be a solution) to tau = 1: try the whole step first,
/// halve the step on failure, double it after easy steps; secant predictor between steps.
NewtonOutcome ContinuationSolve(const SystemFn& f, Eigen::VectorXd& u, int max_iterations,
                                double tolerance);

}  // namespace ftstack::sim::pivot::detail
