#include "calibration/fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

namespace ftstack::cal {
namespace {

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
    if (q) {
      for (std::size_t i = 0; i < pairs.size(); ++i)
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

bool UsesTemp(ModelKind k) { return k == ModelKind::kLinearTemp || k == ModelKind::kQuadraticTemp; }
bool UsesQuad(ModelKind k) { return k == ModelKind::kQuadratic || k == ModelKind::kQuadraticTemp; }

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
            MatrixXd& y) const {
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

 private:
  const RigData& d_;
  const Layout& layout_;
  const VectorXd& offset_;
  double t_ref_;
  const VectorXd& mu_;
  const Eigen::Matrix<double, 6, 1>& mu_y_;
};

constexpr std::size_t kChunk = 4096;

/// Coefficients (in centred, unscaled feature space) of one candidate trained on `train`.
struct Solved {
  MatrixXd beta;  // q × 6 over the model's columns
  double p_eff = 0.0;
};

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

double Condition(const MatrixXd& gram) {
  Eigen::SelfAdjointEigenSolver<MatrixXd> es(gram);
  const double lo = es.eigenvalues().minCoeff();
  const double hi = es.eigenvalues().maxCoeff();
  if (!(lo > 0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(hi / lo);
}

}  // namespace

const char* ToString(ModelKind kind) {
  switch (kind) {
    case ModelKind::kLinear:
      return "linear";
    case ModelKind::kLinearTemp:
      return "linear-temp";
    case ModelKind::kQuadratic:
      return "quadratic";
    case ModelKind::kQuadraticTemp:
      return "quadratic-temp";
  }
  return "?";
}

std::optional<ModelKind> ParseModelKind(const std::string& name) {
  for (ModelKind k : {ModelKind::kLinear, ModelKind::kLinearTemp, ModelKind::kQuadratic,
                      ModelKind::kQuadraticTemp}) {
    if (name == ToString(k)) return k;
  }
  return std::nullopt;
}

std::vector<int> DetectBlocks(const Eigen::MatrixXd& wrench, const BlockOptions& options,
                              int* block_count, std::string* method) {
  const auto rows = static_cast<std::size_t>(wrench.rows());
  std::array<double, 6> scale = options.scale;
  for (int a = 0; a < 6; ++a) {
    if (!(scale[static_cast<std::size_t>(a)] > 0)) {
      scale[static_cast<std::size_t>(a)] = rows > 0 ? wrench.col(a).cwiseAbs().maxCoeff() : 0.0;
    }
  }
  // The largest axis scale stands in for axes that never move (avoids dividing by zero).
  const double big = *std::max_element(scale.begin(), scale.end());
  for (double& s : scale) {
    if (!(s > 1e-9 * big) || !(s > 0)) s = big > 0 ? big : 1.0;
  }
  // Runs within tolerance of their first row.
  struct Run {
    std::size_t begin, end;
  };
  std::vector<Run> runs;
  std::size_t start = 0;
  for (std::size_t i = 1; i <= rows; ++i) {
    bool split = i == rows;
    if (!split) {
      for (int a = 0; a < 6 && !split; ++a) {
        const auto ii = static_cast<Eigen::Index>(i);
        const auto ss = static_cast<Eigen::Index>(start);
        split = std::fabs(wrench(ii, a) - wrench(ss, a)) >
                options.hold_tolerance * scale[static_cast<std::size_t>(a)];
      }
    }
    if (split) {
      runs.push_back({start, i});
      start = i;
    }
  }
  // A slow ramp also breaks into runs within tolerance; holds are the long runs: at least a
  // fifth of the "N50" length (runs at least that long cover half of the rows).
  std::vector<std::size_t> lengths;
  for (const Run& r : runs) lengths.push_back(r.end - r.begin);
  std::sort(lengths.rbegin(), lengths.rend());
  std::size_t n50 = 0;
  std::size_t acc = 0;
  for (std::size_t len : lengths) {
    acc += len;
    n50 = len;
    if (2 * acc >= rows) break;
  }
  const std::size_t min_hold = std::max(options.min_hold_rows, n50 / 5);
  std::vector<Run> holds;
  std::size_t covered = 0;
  for (const Run& r : runs) {
    if (r.end - r.begin >= min_hold) {
      holds.push_back(r);
      covered += r.end - r.begin;
    }
  }
  std::vector<int> block(rows, 0);
  if (holds.size() >= 2 && static_cast<double>(covered) >= 0.3 * static_cast<double>(rows)) {
    // Transition rows join the nearest hold (split at the midpoint between holds).
    for (std::size_t h = 0; h < holds.size(); ++h) {
      const std::size_t lo = h == 0 ? 0 : (holds[h - 1].end + holds[h].begin) / 2;
      const std::size_t hi = h + 1 == holds.size() ? rows : (holds[h].end + holds[h + 1].begin) / 2;
      for (std::size_t i = lo; i < hi; ++i) block[i] = static_cast<int>(h);
    }
    *block_count = static_cast<int>(holds.size());
    *method = "holds";
  } else {
    const std::size_t k = std::max<std::size_t>(2, std::min(options.continuous_blocks, rows));
    for (std::size_t i = 0; i < rows; ++i) block[i] = static_cast<int>(i * k / rows);
    *block_count = static_cast<int>(k);
    *method = "chunks";
  }
  return block;
}

RigData RigDataFromRecording(const Recording& rec, const BlockOptions& options) {
  RigData d;
  d.path = rec.path;
  const std::size_t n = rec.BridgeCount();
  if (n < 1 || n > fw::kMaxChannels) {
    throw RecordingError(rec.path + ": needs bridge columns b0 … b{N-1} with 1 <= N <= 8, has " +
                         std::to_string(n));
  }
  const std::size_t rows = rec.rows();
  d.bridges.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(n));
  d.wrench.resize(static_cast<Eigen::Index>(rows), 6);
  for (std::size_t c = 0; c < n; ++c) {
    const auto& col = rec.Column("b" + std::to_string(c));
    for (std::size_t i = 0; i < rows; ++i) {
      d.bridges(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = col[i];
    }
  }
  for (std::size_t a = 0; a < 6; ++a) {
    const auto& col = rec.Column(WrenchColumns()[a]);
    for (std::size_t i = 0; i < rows; ++i) {
      d.wrench(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(a)) = col[i];
    }
  }
  if (rec.Has("temp_C")) {
    const auto& col = rec.Column("temp_C");
    d.temp_c = Eigen::Map<const VectorXd>(col.data(), static_cast<Eigen::Index>(rows));
  }
  if (rec.Has("t")) {
    d.t_s = rec.Column("t");
  } else {
    d.t_s.resize(rows);
    std::iota(d.t_s.begin(), d.t_s.end(), 0.0);
  }
  const char* label = rec.Has("block") ? "block" : rec.Has("pose") ? "pose" : nullptr;
  if (label != nullptr) {
    const auto& col = rec.Column(label);
    std::map<double, int> ids;
    d.block.resize(rows);
    for (std::size_t i = 0; i < rows; ++i) {
      auto it = ids.find(col[i]);
      if (it == ids.end()) it = ids.emplace(col[i], static_cast<int>(ids.size())).first;
      d.block[i] = it->second;
    }
    d.block_count = static_cast<int>(ids.size());
    d.block_method = std::string("column ") + label;
  } else {
    d.block = DetectBlocks(d.wrench, options, &d.block_count, &d.block_method);
  }
  return d;
}

double LoadSetCondition(const Eigen::MatrixXd& wrench, const std::array<double, 6>& rated) {
  MatrixXd g = MatrixXd::Zero(7, 7);
  Eigen::Matrix<double, 7, 1> u;
  for (Eigen::Index i = 0; i < wrench.rows(); ++i) {
    u(0) = 1.0;
    for (int a = 0; a < 6; ++a) {
      const double r = rated[static_cast<std::size_t>(a)];
      u(1 + a) = wrench(i, a) / (r > 0 ? r : 1.0);
    }
    g.selfadjointView<Eigen::Lower>().rankUpdate(u);
  }
  g = g.selfadjointView<Eigen::Lower>();
  return Condition(g);
}

FitResult FitCalibration(const RigData& d, const FitOptions& options) {
  const auto rows = static_cast<std::size_t>(d.bridges.rows());
  const int n = static_cast<int>(d.bridges.cols());
  if (n < 1 || n > static_cast<int>(fw::kMaxChannels)) {
    throw std::invalid_argument(d.path + ": needs 1 to 8 bridge channels");
  }
  if (d.block_count < 2) throw std::invalid_argument(d.path + ": needs at least 2 load blocks");
  if (!d.bridges.allFinite() || !d.wrench.allFinite() ||
      (d.temp_c.size() > 0 && !d.temp_c.allFinite())) {
    throw std::invalid_argument(d.path + ": data contain NaN or infinity");
  }
  FitResult res;
  res.rows = rows;
  res.block_count = d.block_count;
  res.block_method = d.block_method;
  for (int a = 0; a < 6; ++a) {
    double r = options.rated[static_cast<std::size_t>(a)];
    if (!(r > 0)) r = d.wrench.col(a).cwiseAbs().maxCoeff();
    if (!(r > 0)) r = 1.0;
    res.rated[static_cast<std::size_t>(a)] = r;
  }
  // Temperature is usable when it varies by more than 1 °C.
  const bool has_temp = d.temp_c.size() == static_cast<Eigen::Index>(rows) &&
                        d.temp_c.maxCoeff() - d.temp_c.minCoeff() > 1.0;
  std::vector<ModelKind> models = options.models;
  if (models.empty()) {
    models = {ModelKind::kLinear, ModelKind::kQuadratic};
    if (has_temp) {
      models.push_back(ModelKind::kLinearTemp);
      models.push_back(ModelKind::kQuadraticTemp);
    }
  }
  for (ModelKind k : models) {
    if (UsesTemp(k) && !has_temp) {
      throw std::invalid_argument(d.path + ": model " + std::string(ToString(k)) +
                                  " needs a temp_C column that varies by more than 1 °C");
    }
  }
  const bool want_quad = std::any_of(models.begin(), models.end(), UsesQuad);
  const bool want_temp = std::any_of(models.begin(), models.end(), UsesTemp);
  // With neither requested, the layout holds only what is needed (speed on large inputs).
  Layout layout(n, want_temp);
  if (!want_quad) {
    layout.pairs.clear();
    layout.total = layout.quad_start;
  }

  // Offsets: the bridges' mean over the unloaded rows (all loads within 2 % of rated), else the
  // mean over all rows. Reference temperature: the median, on a 0.01 °C grid.
  VectorXd offset = VectorXd::Zero(n);
  std::size_t unloaded = 0;
  for (std::size_t i = 0; i < rows; ++i) {
    bool zero = true;
    for (int a = 0; a < 6 && zero; ++a) {
      zero = std::fabs(d.wrench(static_cast<Eigen::Index>(i), a)) <=
             0.02 * res.rated[static_cast<std::size_t>(a)];
    }
    if (zero) {
      offset += d.bridges.row(static_cast<Eigen::Index>(i)).transpose();
      ++unloaded;
    }
  }
  if (unloaded >= 10) {
    offset /= static_cast<double>(unloaded);
  } else {
    offset = d.bridges.colwise().mean().transpose();
  }
  double t_ref = 20.0;
  double t_min = 0.0;
  double t_max = 0.0;
  if (want_temp) {
    std::vector<double> tv(d.temp_c.data(), d.temp_c.data() + rows);
    std::nth_element(tv.begin(), tv.begin() + static_cast<std::ptrdiff_t>(rows / 2), tv.end());
    t_ref = std::round(tv[rows / 2] * 100.0) / 100.0;
    t_min = d.temp_c.minCoeff() - 1.0;
    t_max = d.temp_c.maxCoeff() + 1.0;
  }

  // Folds over whole blocks: block b (in order of first row) goes to fold b mod K, so
  // neighbouring blocks (an up and a down sweep) land in different folds.
  const int k_folds = std::max(2, std::min(options.folds, d.block_count));
  res.folds = k_folds;
  std::vector<std::vector<std::size_t>> fold_rows(static_cast<std::size_t>(k_folds));
  for (std::size_t i = 0; i < rows; ++i) {
    fold_rows[static_cast<std::size_t>(d.block[i] % k_folds)].push_back(i);
  }
  const int p = layout.total;
  // Global means of the features and targets (pass 1).
  VectorXd mu = VectorXd::Zero(p);
  Eigen::Matrix<double, 6, 1> mu_y = d.wrench.colwise().mean().transpose();
  {
    std::vector<double> x(static_cast<std::size_t>(n));
    std::vector<double> row(static_cast<std::size_t>(p));
    for (std::size_t i = 0; i < rows; ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      for (int c = 0; c < n; ++c) x[static_cast<std::size_t>(c)] = d.bridges(r, c) - offset(c);
      layout.Row(x.data(), layout.temp ? d.temp_c(r) - t_ref : 0.0, row.data());
      for (int j = 0; j < p; ++j) mu(j) += row[static_cast<std::size_t>(j)];
    }
    mu /= static_cast<double>(rows);
    mu(0) = 0.0;
  }
  FeatureBuilder builder(d, layout, offset, t_ref, mu, mu_y);
  // Pass 2: sufficient statistics per fold.
  std::vector<FoldStats> stats(static_cast<std::size_t>(k_folds));
  FoldStats total;
  total.g = MatrixXd::Zero(p, p);
  total.xy = MatrixXd::Zero(p, 6);
  MatrixXd f;
  MatrixXd y;
  for (int k = 0; k < k_folds; ++k) {
    FoldStats& s = stats[static_cast<std::size_t>(k)];
    s.g = MatrixXd::Zero(p, p);
    s.xy = MatrixXd::Zero(p, 6);
    const auto& idx = fold_rows[static_cast<std::size_t>(k)];
    for (std::size_t b = 0; b < idx.size(); b += kChunk) {
      const std::size_t e = std::min(idx.size(), b + kChunk);
      builder.Fill(idx, b, e, f, y);
      s.g.selfadjointView<Eigen::Lower>().rankUpdate(f.transpose());
      s.xy.noalias() += f.transpose() * y;
      s.yy += y.colwise().squaredNorm().transpose();
    }
    s.g = s.g.selfadjointView<Eigen::Lower>();
    s.rows = idx.size();
    total.g += s.g;
    total.xy += s.xy;
    total.yy += s.yy;
    total.rows += s.rows;
  }
  // Standardisation scale: 1 / RMS of each centred feature.
  VectorXd scale = VectorXd::Ones(p);
  for (int j = 1; j < p; ++j) {
    const double ms = total.g(j, j) / static_cast<double>(rows);
    scale(j) = ms > 0 ? 1.0 / std::sqrt(ms) : 1.0;
  }
  std::vector<FoldStats> train;
  train.reserve(stats.size());
  for (const FoldStats& s : stats) train.push_back(Subtract(total, s));

  // Cross-validate every candidate.
  auto score_of = [&](const Eigen::Matrix<double, 6, 1>& sse, std::array<double, 6>* rms) {
    double score = 0.0;
    for (std::size_t a = 0; a < 6; ++a) {
      (*rms)[a] = std::sqrt(sse(static_cast<Eigen::Index>(a)) / static_cast<double>(rows));
      score += std::pow((*rms)[a] / res.rated[a], 2) / 6.0;
    }
    return score;
  };
  for (ModelKind kind : models) {
    const std::vector<int> cols = layout.Columns(kind);
    if (cols.size() * 2 > rows) continue;  // not enough rows for this model
    for (double lambda : options.lambdas) {
      Eigen::Matrix<double, 6, 1> sse = Eigen::Matrix<double, 6, 1>::Zero();
      for (int k = 0; k < k_folds; ++k) {
        Solved s = Solve(train[static_cast<std::size_t>(k)], cols, scale, lambda);
        if (UsesTemp(kind)) {
          ProjectTemperature(layout, cols, train[static_cast<std::size_t>(k)], s.beta, nullptr,
                             nullptr);
        }
        sse += HeldOutSse(stats[static_cast<std::size_t>(k)], cols, s.beta);
      }
      CandidateScore c;
      c.kind = kind;
      c.lambda = lambda;
      c.features = static_cast<int>(cols.size());
      c.score = score_of(sse, &c.rms_si);
      if (std::isfinite(c.score)) res.candidates.push_back(c);
    }
  }
  if (res.candidates.empty()) throw std::invalid_argument(d.path + ": too few rows for any model");
  // The best; then the simplest candidate within the tolerance of it.
  const auto best = std::min_element(
      res.candidates.begin(), res.candidates.end(),
      [](const CandidateScore& a, const CandidateScore& b) { return a.score < b.score; });
  const double limit = best->score * (1.0 + options.simpler_tolerance);
  int fewest = best->features;
  for (const CandidateScore& c : res.candidates) {
    if (c.score <= limit) fewest = std::min(fewest, c.features);
  }
  const CandidateScore* chosen = nullptr;
  for (const CandidateScore& c : res.candidates) {
    if (c.features == fewest && (chosen == nullptr || c.score < chosen->score)) chosen = &c;
  }
  res.kind = chosen->kind;
  res.lambda = chosen->lambda;
  res.heldout_rms_si = chosen->rms_si;
  const std::vector<int> cols = layout.Columns(res.kind);

  // Held-out residuals of the chosen model, row by row.
  res.heldout_residual.resize(static_cast<Eigen::Index>(rows), 6);
  for (int k = 0; k < k_folds; ++k) {
    Solved s = Solve(train[static_cast<std::size_t>(k)], cols, scale, res.lambda);
    if (UsesTemp(res.kind)) {
      ProjectTemperature(layout, cols, train[static_cast<std::size_t>(k)], s.beta, nullptr,
                         nullptr);
    }
    const auto& idx = fold_rows[static_cast<std::size_t>(k)];
    for (std::size_t b = 0; b < idx.size(); b += kChunk) {
      const std::size_t e = std::min(idx.size(), b + kChunk);
      builder.Fill(idx, b, e, f, y);
      MatrixXd fc(f.rows(), static_cast<Eigen::Index>(cols.size()));
      for (std::size_t j = 0; j < cols.size(); ++j)
        fc.col(static_cast<Eigen::Index>(j)) = f.col(cols[j]);
      const MatrixXd r = fc * s.beta - y;
      for (Eigen::Index i = 0; i < r.rows(); ++i) {
        res.heldout_residual.row(static_cast<Eigen::Index>(idx[b + static_cast<std::size_t>(i)])) =
            r.row(i);
      }
    }
  }
  for (int a = 0; a < 6; ++a) {
    std::vector<double> v(rows);
    for (std::size_t i = 0; i < rows; ++i) {
      v[i] = std::fabs(res.heldout_residual(static_cast<Eigen::Index>(i), a));
    }
    res.heldout_p95_si[static_cast<std::size_t>(a)] = Percentile95(std::move(v));
  }
  // Per-block scores.
  res.blocks.resize(static_cast<std::size_t>(d.block_count));
  std::vector<double> block_ss(static_cast<std::size_t>(d.block_count), 0.0);
  for (std::size_t i = 0; i < rows; ++i) {
    BlockScore& b = res.blocks[static_cast<std::size_t>(d.block[i])];
    if (b.rows == 0) b.t_start_s = d.t_s[i];
    b.t_end_s = d.t_s[i];
    ++b.rows;
    for (std::size_t a = 0; a < 6; ++a) {
      const auto ii = static_cast<Eigen::Index>(i);
      const auto aa = static_cast<Eigen::Index>(a);
      b.mean_wrench[a] += d.wrench(ii, aa);
      block_ss[static_cast<std::size_t>(d.block[i])] +=
          std::pow(res.heldout_residual(ii, aa) / res.rated[a] * 100.0, 2) / 6.0;
    }
  }
  for (std::size_t bi = 0; bi < res.blocks.size(); ++bi) {
    BlockScore& b = res.blocks[bi];
    b.block = static_cast<int>(bi);
    if (b.rows > 0) {
      for (double& w : b.mean_wrench) w /= static_cast<double>(b.rows);
      b.rms_pct = std::sqrt(block_ss[bi] / static_cast<double>(b.rows));
    }
  }
  std::sort(res.blocks.begin(), res.blocks.end(),
            [](const BlockScore& a, const BlockScore& b) { return a.rms_pct > b.rms_pct; });

  // Final fit on all rows.
  Solved s = Solve(total, cols, scale, res.lambda);
  VectorXd alpha;
  VectorXd gamma;
  if (UsesTemp(res.kind)) ProjectTemperature(layout, cols, total, s.beta, &alpha, &gamma);
  {
    // Training residual σ and the parameter part of the uncertainty.
    const Eigen::Matrix<double, 6, 1> sse = HeldOutSse(total, cols, s.beta);
    const double dof = std::max(1.0, static_cast<double>(rows) - s.p_eff);
    for (std::size_t a = 0; a < 6; ++a) {
      const double sigma = std::sqrt(sse(static_cast<Eigen::Index>(a)) / dof);
      res.residual_sigma_si[a] = sigma;
      res.fit_uncertainty_si[a] = sigma * std::sqrt(s.p_eff / static_cast<double>(rows));
    }
    const auto q = static_cast<Eigen::Index>(cols.size());
    MatrixXd g(q, q);
    for (Eigen::Index i = 0; i < q; ++i) {
      for (Eigen::Index j = 0; j < q; ++j) {
        const int ci = cols[static_cast<std::size_t>(i)];
        const int cj = cols[static_cast<std::size_t>(j)];
        g(i, j) = total.g(ci, cj) * scale(ci) * scale(cj) / static_cast<double>(rows);
      }
    }
    res.design_condition = Condition(g);
  }
  res.load_condition = LoadSetCondition(d.wrench, res.rated);

  // Into the calibration's form: undo the centring (intercept = μ_y + β0 − Σ β_j μ_j).
  fw::FloatCalibration& cal = res.cal;
  cal.channel_count = static_cast<std::uint8_t>(n);
  std::map<int, Eigen::Index> pos;
  for (std::size_t i = 0; i < cols.size(); ++i) pos[cols[i]] = static_cast<Eigen::Index>(i);
  for (int a = 0; a < 6; ++a) {
    double c0 = mu_y(a) + s.beta(0, a);
    for (std::size_t i = 1; i < cols.size(); ++i)
      c0 -= s.beta(static_cast<Eigen::Index>(i), a) * mu(cols[i]);
    cal.bias[static_cast<std::size_t>(a)] = c0;
    for (int c = 0; c < n; ++c) {
      cal.matrix[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)] =
          s.beta(pos.at(1 + c), a);
    }
  }
  for (int c = 0; c < n; ++c) cal.offset_mvv[static_cast<std::size_t>(c)] = offset(c);
  if (UsesQuad(res.kind)) {
    cal.product_count = static_cast<std::uint8_t>(layout.pairs.size());
    for (std::size_t k = 0; k < layout.pairs.size(); ++k) {
      cal.products[k] = fw::ProductTerm{static_cast<std::uint8_t>(layout.pairs[k].first),
                                        static_cast<std::uint8_t>(layout.pairs[k].second)};
      for (int a = 0; a < 6; ++a) {
        cal.product_matrix[static_cast<std::size_t>(a)][k] =
            s.beta(pos.at(layout.quad_start + static_cast<int>(k)), a);
      }
    }
  }
  if (UsesTemp(res.kind)) {
    cal.temperature_compensated = true;
    cal.temp_ref_c = t_ref;
    cal.temp_min_c = t_min;
    cal.temp_max_c = t_max;
    for (int c = 0; c < n; ++c) {
      cal.bias_slope_mvv_per_c[static_cast<std::size_t>(c)] = alpha(c);
      cal.gain_slope_per_c[static_cast<std::size_t>(c)] = gamma(c);
    }
  }
  return res;
}

double LoadSetCondition(const std::vector<Wrench>& loads, const Wrench& rated) {
  Eigen::MatrixXd w(static_cast<Eigen::Index>(loads.size()), 6);
  for (std::size_t i = 0; i < loads.size(); ++i)
    w.row(static_cast<Eigen::Index>(i)) = loads[i].transpose();
  std::array<double, 6> r{};
  for (int a = 0; a < 6; ++a) r[static_cast<std::size_t>(a)] = rated(a);
  return LoadSetCondition(w, r);
}

}  // namespace ftstack::cal
