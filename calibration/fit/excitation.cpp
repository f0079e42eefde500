#include "calibration/fit/excitation.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/fit.hpp"

namespace ftstack::cal {

ExcitationReport CheckExcitation(const Eigen::MatrixXd& wrench, const std::array<double, 6>& rated,
                                 const ExcitationOptions& options) {
  const Eigen::Index rows = wrench.rows();
  if (rows < 2 || wrench.cols() != 6) {
    throw std::invalid_argument("excitation check needs at least 2 rows of 6 axes");
  }
  Eigen::MatrixXd z(rows, 6);
  for (int a = 0; a < 6; ++a) {
    const double r = rated[static_cast<std::size_t>(a)];
    if (!(r > 0) || !std::isfinite(r)) {
      throw std::invalid_argument("excitation check needs a positive rated range on every axis");
    }
    z.col(a) = wrench.col(a) / r;
  }
  ExcitationReport rep;
  for (int a = 0; a < 6; ++a) {
    AxisExcitation& e = rep.axes[static_cast<std::size_t>(a)];
    e.range_fraction = z.col(a).maxCoeff() - z.col(a).minCoeff();
    // Least squares of this axis on [1, the other five]; the residual is what only it carries.
    Eigen::MatrixXd others(rows, 6);
    others.col(0).setOnes();
    for (int b = 0, k = 1; b < 6; ++b) {
      if (b != a) others.col(k++) = z.col(b);
    }
    const Eigen::VectorXd coef = others.colPivHouseholderQr().solve(z.col(a));
    const Eigen::VectorXd residual = z.col(a) - others * coef;
    e.independent_fraction = std::sqrt(residual.squaredNorm() / static_cast<double>(rows));
    e.excited = e.range_fraction >= options.min_range_fraction &&
                e.independent_fraction >= options.min_independent_fraction;
    if (!e.excited) rep.unexcited = static_cast<std::uint8_t>(rep.unexcited | (1u << a));
  }
  rep.condition = LoadSetCondition(wrench, rated);
  return rep;
}

std::string ExcitationReport::Refusal(const std::array<double, 6>& rated,
                                      const ExcitationOptions& options) const {
  if (unexcited == 0) return "";
  std::string s = std::string(unexcited & (unexcited - 1) ? "axes " : "axis ") +
                  AxisList(unexcited) + " not excited by the rig (";
  bool first = true;
  for (std::size_t a = 0; a < 6; ++a) {
    if ((unexcited & (1u << a)) == 0) continue;
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "%s%s: load range %.1f %% of rated %g %s, needs %.0f %%; independent of the "
                  "other axes %.1f %%, needs %.0f %%",
                  first ? "" : "; ", kAxisNames[a], 100.0 * axes[a].range_fraction, rated[a],
                  a < 3 ? "N" : "N·m", 100.0 * options.min_range_fraction,
                  100.0 * axes[a].independent_fraction, 100.0 * options.min_independent_fraction);
    s += buf;
    first = false;
  }
  char cond[64];
  std::snprintf(cond, sizeof cond, "; load set condition number %.3g)", condition);
  return s + cond;
}

}  // namespace ftstack::cal
