// Internals of the calibration fit: feature layout, per-fold statistics, ridge solve.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <utility>
#include <vector>

#include "calibration/fit/fit.hpp"

namespace ftstack::cal::fit_detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// Feature layout of the largest model for N channels: 1, x (N), [ΔT, x·ΔT (N)], [x_a·x_b].
struct Layout {
  int n = 0;
  bool temp = false;
  int temp_start = -1;  // index of ΔT
  int quad_start = -1;
  int total = 0;
  std::vector<std::pair<int, int>> pairs;

  Layout(int channels, bool with_temp) : n(channels), temp(with_temp) {
    total = 1 + n;
    if (temp) {
      temp_start = total;
      total += 1 + n;
    }
    quad_start = total;
    for (int a = 0; a < n; ++a) {
      for (int b = a; b < n; ++b) pairs.emplace_back(a, b);
    }
    total += static_cast<int>(pairs.size());
  }

  /// Column indices a model uses.
  [[nodiscard]] std::vector<int> Columns(ModelKind kind) const {
    std::vector<int> cols;
    for (int i = 0; i <= n; ++i) cols.push_back(i);
    const bool t = kind == ModelKind::kLinearTemp || kind == ModelKind::kQuadraticTemp;
    const bool q = kind == ModelKind::kQuadratic || kind == ModelKind::kQuadraticTemp;
    if (t) {
      for (int i = 0; i <= n; ++i) cols.push_back(temp_start + i);
    }
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const bool square = pairs[i].first == pairs[i].second;
      if (q || (kind == ModelKind::kQuadraticDiag && square))
        cols.push_back(quad_start + static_cast<int>(i));
    }
    return cols;
  }

  /// Features of one row (x = bridge − offset, dt = T − Tref).
  void Row(const double* x, double dt, double* f) const {
    f[0] = 1.0;
    for (int c = 0; c < n; ++c) f[1 + c] = x[c];
    if (temp) {
      f[temp_start] = dt;
      for (int c = 0; c < n; ++c) f[temp_start + 1 + c] = x[c] * dt;
    }
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      f[quad_start + static_cast<int>(k)] = x[pairs[k].first] * x[pairs[k].second];
    }
  }
};

inline bool UsesTemp(ModelKind k) {
  return k == ModelKind::kLinearTemp || k == ModelKind::kQuadraticTemp;
}
inline bool UsesQuad(ModelKind k) {
  return k == ModelKind::kQuadratic || k == ModelKind::kQuadraticTemp ||
         k == ModelKind::kQuadraticDiag;
}

/// Sufficient statistics of one fold, features centred by the global means (column 0 stays 1).
struct FoldStats {
  MatrixXd g;   // p × p
  MatrixXd xy;  // p × 6
  Eigen::Matrix<double, 6, 1> yy = Eigen::Matrix<double, 6, 1>::Zero();
  std::size_t rows = 0;
};

/// The centred feature and target matrices for a set of rows, built in chunks by a callback.
class FeatureBuilder {
 public:
  FeatureBuilder(const RigData& d, const Layout& layout, const VectorXd& offset, double t_ref,
                 const VectorXd& mu, const Eigen::Matrix<double, 6, 1>& mu_y)
      : d_(d), layout_(layout), offset_(offset), t_ref_(t_ref), mu_(mu), mu_y_(mu_y) {}

  /// Fills rows idx[begin, end) into f (count × p) and y (count × 6).
  void Fill(const std::vector<std::size_t>& idx, std::size_t begin, std::size_t end, MatrixXd& f,
            MatrixXd& y) const;

 private:
  const RigData& d_;
  const Layout& layout_;
  const VectorXd& offset_;
  double t_ref_;
  const VectorXd& mu_;
  const Eigen::Matrix<double, 6, 1>& mu_y_;
};

inline constexpr std::size_t kChunk = 4096;

/// Coefficients (in centred, unscaled feature space) of one candidate trained on `train`.
struct Solved {
  MatrixXd beta;  // q × 6 over the model's columns
  double p_eff = 0.0;
};

/// Ridge solve (penalty lambda·rows on the standardised non-intercept columns).
[[nodiscard]] Solved Solve(const FoldStats& train, const std::vector<int>& cols,
                           const VectorXd& scale, double lambda);

/// Replaces the general temperature coefficients by the per-channel form (bias slope α, gain
/// slope γ): A = −M·α, G_c = −M_c·γ_c, then refits the intercept on the training statistics.
void ProjectTemperature(const Layout& layout, const std::vector<int>& cols, const FoldStats& train,
                        MatrixXd& beta, VectorXd* alpha, VectorXd* gamma);

/// Held-out SSE per axis of β on a fold's statistics.
[[nodiscard]] Eigen::Matrix<double, 6, 1> HeldOutSse(const FoldStats& test,
                                                     const std::vector<int>& cols,
                                                     const MatrixXd& beta);

/// The statistics of `total` without those of `part` (the training set of a fold).
[[nodiscard]] FoldStats Subtract(const FoldStats& total, const FoldStats& part);

/// The 95th percentile (nearest rank) of the values; 0 for none.
[[nodiscard]] double Percentile95(std::vector<double> v);

}  // namespace ftstack::cal::fit_detail
