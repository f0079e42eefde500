#include "diagnosis/engine/quantisation.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ftstack::diag {

double InferGridStep(const double* values, std::size_t n) {
  if (n < 8) return 0.0;
  const std::size_t every = std::max<std::size_t>(1, n / kGridSampleRows);
  std::vector<double> v;
  v.reserve(n / every + 1);
  double peak = 0.0;
  for (std::size_t i = 0; i < n; i += every) {
    const double x = values[i];
    v.push_back(x);
    peak = std::max(peak, std::fabs(x));
  }
  std::sort(v.begin(), v.end());
  // Levels: values equal to within the rounding of a printed or converted number.
  const double tol = 1e-9 * peak + 1e-15;
  std::vector<double> levels;
  for (double x : v) {
    if (levels.empty() || x - levels.back() > tol) levels.push_back(x);
  }
  if (levels.size() < 3 || levels.size() * 4 > v.size()) return 0.0;
  double step = levels.back() - levels.front();
  for (std::size_t k = 1; k < levels.size(); ++k) step = std::min(step, levels[k] - levels[k - 1]);
  if (step <= tol) return 0.0;
  std::size_t on_grid = 0;
  for (double x : levels) {
    const double m = (x - levels.front()) / step;
    if (std::fabs(m - std::round(m)) < 0.05) ++on_grid;
  }
  return on_grid >= 0.99 * static_cast<double>(levels.size()) ? step : 0.0;
}

Quantisation FindQuantisation(const DiagData& d) {
  Quantisation q;
  const auto nc = static_cast<Eigen::Index>(d.real_mvv.cols());
  q.step_mvv = Eigen::VectorXd::Zero(nc);
  if (d.real_unit_symbol == "counts" && d.real_units_per_mvv > 0) {
    q.step_mvv.setConstant(1.0 / d.real_units_per_mvv);
    q.source = "declared";
    return q;
  }
  for (Eigen::Index c = 0; c < nc; ++c)
    q.step_mvv(c) = InferGridStep(d.real_mvv.col(c).data(), d.rows());
  if (q.quantised()) q.source = "inferred";
  return q;
}

}  // namespace ftstack::diag
