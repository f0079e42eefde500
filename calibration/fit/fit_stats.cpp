#include "calibration/fit/fit_stats.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace ftstack::cal::fit_detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;

void FeatureBuilder::Fill(const std::vector<std::size_t>& idx, std::size_t begin, std::size_t end,
                          MatrixXd& f, MatrixXd& y) const {
  const int p = layout_.total;
  const int n = layout_.n;
  const std::size_t count = end - begin;
  f.resize(static_cast<Eigen::Index>(count), p);
  y.resize(static_cast<Eigen::Index>(count), 6);
  std::vector<double> x(static_cast<std::size_t>(n));
  std::vector<double> row(static_cast<std::size_t>(p));
  for (std::size_t i = 0; i < count; ++i) {
    const auto r = static_cast<Eigen::Index>(idx[begin + i]);
    for (int c = 0; c < n; ++c) x[static_cast<std::size_t>(c)] = d_.bridges(r, c) - offset_(c);
    const double dt = layout_.temp ? d_.temp_c(r) - t_ref_ : 0.0;
    layout_.Row(x.data(), dt, row.data());
    const auto ii = static_cast<Eigen::Index>(i);
    f(ii, 0) = 1.0;
    for (int j = 1; j < p; ++j) f(ii, j) = row[static_cast<std::size_t>(j)] - mu_(j);
    for (int a = 0; a < 6; ++a) y(ii, a) = d_.wrench(r, a) - mu_y_(a);
  }
}

Solved Solve(const FoldStats& train, const std::vector<int>& cols, const VectorXd& scale,
             double lambda) {
  const auto q = static_cast<Eigen::Index>(cols.size());
  MatrixXd g(q, q);
  MatrixXd xy(q, 6);
  for (Eigen::Index i = 0; i < q; ++i) {
    const int ci = cols[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < q; ++j) {
      g(i, j) = train.g(ci, cols[static_cast<std::size_t>(j)]) * scale(ci) *
                scale(cols[static_cast<std::size_t>(j)]);
    }
    xy.row(i) = train.xy.row(ci) * scale(ci);
  }
  MatrixXd a = g;
  const double n = static_cast<double>(train.rows);
  for (Eigen::Index i = 1; i < q; ++i) a(i, i) += lambda * n;
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(a);
  Solved s;
  s.beta = cod.solve(xy);
  s.p_eff = (cod.solve(g)).trace();
  for (Eigen::Index i = 0; i < q; ++i) s.beta.row(i) *= scale(cols[static_cast<std::size_t>(i)]);
  return s;
}

/// Replaces the general temperature coefficients by the per-channel form (bias slope α, gain
/// slope γ): A = −M·α, G_c = −M_c·γ_c, then refits the intercept on the training statistics.
void ProjectTemperature(const Layout& layout, const std::vector<int>& cols, const FoldStats& train,
                        MatrixXd& beta, VectorXd* alpha, VectorXd* gamma) {
  const int n = layout.n;
  std::map<int, Eigen::Index> pos;
  for (std::size_t i = 0; i < cols.size(); ++i) pos[cols[i]] = static_cast<Eigen::Index>(i);
  MatrixXd m(6, n);
  for (int c = 0; c < n; ++c) m.col(c) = beta.row(pos.at(1 + c)).transpose();
  const VectorXd a = beta.row(pos.at(layout.temp_start)).transpose();
  VectorXd al = -m.completeOrthogonalDecomposition().solve(a);
  VectorXd ga(n);
  for (int c = 0; c < n; ++c) {
    const VectorXd gc = beta.row(pos.at(layout.temp_start + 1 + c)).transpose();
    const double mm = m.col(c).squaredNorm();
    ga(c) = mm > 0 ? -m.col(c).dot(gc) / mm : 0.0;
  }
  beta.row(pos.at(layout.temp_start)) = (-m * al).transpose();
  for (int c = 0; c < n; ++c) {
    beta.row(pos.at(layout.temp_start + 1 + c)) = (-m.col(c) * ga(c)).transpose();
  }
  // Intercept: mean of (y − Σ_{j>0} β_j f_j) over the training rows.
  const double nr = static_cast<double>(train.rows);
  for (int axis = 0; axis < 6; ++axis) {
    double s = train.xy(0, axis);
    for (std::size_t i = 1; i < cols.size(); ++i) {
      s -= beta(static_cast<Eigen::Index>(i), axis) * train.g(0, cols[i]);
    }
    beta(0, axis) = s / nr;
  }
  if (alpha != nullptr) *alpha = al;
  if (gamma != nullptr) *gamma = ga;
}

/// Held-out SSE per axis of β on a fold's statistics.
Eigen::Matrix<double, 6, 1> HeldOutSse(const FoldStats& test, const std::vector<int>& cols,
                                       const MatrixXd& beta) {
  Eigen::Matrix<double, 6, 1> sse;
  const auto q = static_cast<Eigen::Index>(cols.size());
  MatrixXd g(q, q);
  MatrixXd xy(q, 6);
  for (Eigen::Index i = 0; i < q; ++i) {
    for (Eigen::Index j = 0; j < q; ++j) {
      g(i, j) = test.g(cols[static_cast<std::size_t>(i)], cols[static_cast<std::size_t>(j)]);
    }
    xy.row(i) = test.xy.row(cols[static_cast<std::size_t>(i)]);
  }
  for (int a = 0; a < 6; ++a) {
    const VectorXd b = beta.col(a);
    sse(a) = std::max(0.0, test.yy(a) - 2.0 * b.dot(xy.col(a)) + b.dot(g * b));
  }
  return sse;
}

FoldStats Subtract(const FoldStats& total, const FoldStats& part) {
  FoldStats s;
  s.g = total.g - part.g;
  s.xy = total.xy - part.xy;
  s.yy = total.yy - part.yy;
  s.rows = total.rows - part.rows;
  return s;
}

double Percentile95(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t k =
      static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace ftstack::cal::fit_detail
