#include "calibration/fit/fit.hpp"
#include "calibration/fit/fit_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

namespace ftstack::cal {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

using fit_detail::FeatureBuilder;
using fit_detail::FoldStats;
using fit_detail::HeldOutSse;
using fit_detail::kChunk;
using fit_detail::Layout;
using fit_detail::Percentile95;
using fit_detail::ProjectTemperature;
using fit_detail::Solve;
using fit_detail::Solved;
using fit_detail::Subtract;
using fit_detail::UsesQuad;
using fit_detail::UsesTemp;

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
    case ModelKind::kQuadraticDiag:
      return "quadratic-diag";
  }
  return "?";
}

std::optional<ModelKind> ParseModelKind(const std::string& name) {
  for (ModelKind k : {ModelKind::kLinear, ModelKind::kLinearTemp, ModelKind::kQuadratic,
                      ModelKind::kQuadraticTemp, ModelKind::kQuadraticDiag}) {
    if (name == ToString(k)) return k;
  }
  return std::nullopt;
}

namespace {

/// The rated (or largest seen) load per axis, the scale of the scores.
std::array<double, 6> RatedScale(const RigData& d, const FitOptions& options) {
  std::array<double, 6> rated{};
  for (int a = 0; a < 6; ++a) {
    double r = options.rated[static_cast<std::size_t>(a)];
    if (!(r > 0)) r = d.wrench.col(a).cwiseAbs().maxCoeff();
    if (!(r > 0)) r = 1.0;
    rated[static_cast<std::size_t>(a)] = r;
  }
  return rated;
}

/// The candidate models: the requested ones (checked against the data) or the default set.
std::vector<ModelKind> CandidateModels(const RigData& d, const FitOptions& options) {
  // Temperature is usable when it varies by more than 1 °C.
  const bool has_temp =
      d.temp_c.size() == d.bridges.rows() && d.temp_c.maxCoeff() - d.temp_c.minCoeff() > 1.0;
  std::vector<ModelKind> models = options.models;
  if (models.empty()) {
    models = {ModelKind::kLinear, ModelKind::kQuadraticDiag, ModelKind::kQuadratic};
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
  return models;
}

/// Where the features are measured from: bridge offsets and the temperature reference and range.
struct Reference {
  VectorXd offset;
  double t_ref = 20.0;
  double t_min = 0.0;
  double t_max = 0.0;
};

/// Offsets: the bridges' mean over the unloaded rows (all loads within 2 % of rated), else the
/// mean over all rows. Reference temperature: the median, on a 0.01 °C grid.
Reference FindReference(const RigData& d, const std::array<double, 6>& rated, bool want_temp) {
  const auto rows = static_cast<std::size_t>(d.bridges.rows());
  Reference ref;
  ref.offset = VectorXd::Zero(d.bridges.cols());
  std::size_t unloaded = 0;
  for (std::size_t i = 0; i < rows; ++i) {
    bool zero = true;
    for (int a = 0; a < 6 && zero; ++a) {
      zero = std::fabs(d.wrench(static_cast<Eigen::Index>(i), a)) <=
             0.02 * rated[static_cast<std::size_t>(a)];
    }
    if (zero) {
      ref.offset += d.bridges.row(static_cast<Eigen::Index>(i)).transpose();
      ++unloaded;
    }
  }
  if (unloaded >= 10) {
    ref.offset /= static_cast<double>(unloaded);
  } else {
    ref.offset = d.bridges.colwise().mean().transpose();
  }
  if (want_temp) {
    std::vector<double> tv(d.temp_c.data(), d.temp_c.data() + rows);
    std::nth_element(tv.begin(), tv.begin() + static_cast<std::ptrdiff_t>(rows / 2), tv.end());
    ref.t_ref = std::round(tv[rows / 2] * 100.0) / 100.0;
    ref.t_min = d.temp_c.minCoeff() - 1.0;
    ref.t_max = d.temp_c.maxCoeff() + 1.0;
  }
  return ref;
}

/// The cross-validation folds with their centring and sufficient statistics.
struct Folds {
  int k = 0;
  std::vector<std::vector<std::size_t>> rows;  // row indices per fold
  std::vector<double> unit_fraction;           // validation units in the fold / all units
  VectorXd mu;                                 // global feature means (mu(0) = 0)
  Eigen::Matrix<double, 6, 1> mu_y;            // global target means
  std::vector<FoldStats> stats;                // per fold
  std::vector<FoldStats> train;                // all but that fold
  FoldStats total;
  VectorXd scale;  // standardisation: 1 / RMS of each centred feature
};

/// Folds over whole validation units — temperatures when temperature terms are candidates and
/// the rig held at least three (levels more than 1 °C apart: a temperature model must predict a
/// temperature it never saw), else groups (load directions) when asked for and there are at
/// least three, else blocks: unit u (in order of first row, or coldest first) goes to fold
/// u mod K, so neighbouring blocks (an up and a down sweep) land in different folds. Returns a
/// description.
std::string AssignFolds(const RigData& d, const FitOptions& options, bool temperature_candidates,
                        Folds* out) {
  int levels = 0;
  const std::vector<int> level = temperature_candidates && d.temp_c.size() > 0
                                     ? TemperatureLevels(d.temp_c, 1.0, &levels)
                                     : std::vector<int>{};
  const bool temps = levels >= 3;
  const bool groups =
      !temps && options.by_group && d.group_count >= 3 && d.group.size() == d.block.size();
  const std::vector<int>& unit = temps ? level : groups ? d.group : d.block;
  const int units = temps ? levels : groups ? d.group_count : d.block_count;
  out->k = std::max(2, std::min(options.folds, units));
  out->rows.assign(static_cast<std::size_t>(out->k), {});
  for (std::size_t i = 0; i < unit.size(); ++i) {
    out->rows[static_cast<std::size_t>(unit[i] % out->k)].push_back(i);
  }
  out->unit_fraction.assign(static_cast<std::size_t>(out->k), 0.0);
  for (int u = 0; u < units; ++u)
    out->unit_fraction[static_cast<std::size_t>(u % out->k)] += 1.0 / static_cast<double>(units);
  if (temps) return std::to_string(units) + " temperatures (levels more than 1 °C apart)";
  if (groups) return std::to_string(units) + " groups (" + d.group_method + ")";
  std::string why = options.by_group ? " (fewer than 3 groups)" : "";
  return std::to_string(units) + " load blocks (" + d.block_method + ")" + why;
}

/// Global means of the features and targets (pass 1).
void CentreFeatures(const RigData& d, const Layout& layout, const Reference& ref, Folds* out) {
  const auto rows = static_cast<std::size_t>(d.bridges.rows());
  const int n = layout.n;
  const int p = layout.total;
  out->mu = VectorXd::Zero(p);
  out->mu_y = d.wrench.colwise().mean().transpose();
  std::vector<double> x(static_cast<std::size_t>(n));
  std::vector<double> row(static_cast<std::size_t>(p));
  for (std::size_t i = 0; i < rows; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < n; ++c) x[static_cast<std::size_t>(c)] = d.bridges(r, c) - ref.offset(c);
    layout.Row(x.data(), layout.temp ? d.temp_c(r) - ref.t_ref : 0.0, row.data());
    for (int j = 0; j < p; ++j) out->mu(j) += row[static_cast<std::size_t>(j)];
  }
  out->mu /= static_cast<double>(rows);
  out->mu(0) = 0.0;
}

/// Pass 2: sufficient statistics per fold, their total, the training complements and the scale.
/// With `row_weight`, every row's features and targets are scaled by √w (weighted least squares).
void AccumulateFolds(const FeatureBuilder& builder, int p, std::size_t rows, Folds* out,
                     const std::vector<double>* row_weight = nullptr) {
  out->stats.assign(static_cast<std::size_t>(out->k), {});
  out->total.g = MatrixXd::Zero(p, p);
  out->total.xy = MatrixXd::Zero(p, 6);
  MatrixXd f;
  MatrixXd y;
  for (int k = 0; k < out->k; ++k) {
    FoldStats& s = out->stats[static_cast<std::size_t>(k)];
    s.g = MatrixXd::Zero(p, p);
    s.xy = MatrixXd::Zero(p, 6);
    const auto& idx = out->rows[static_cast<std::size_t>(k)];
    for (std::size_t b = 0; b < idx.size(); b += kChunk) {
      const std::size_t e = std::min(idx.size(), b + kChunk);
      builder.Fill(idx, b, e, f, y);
      if (row_weight != nullptr) {
        for (std::size_t i = b; i < e; ++i) {
          const double w = std::sqrt((*row_weight)[idx[i]]);
          f.row(static_cast<Eigen::Index>(i - b)) *= w;
          y.row(static_cast<Eigen::Index>(i - b)) *= w;
        }
      }
      s.g.selfadjointView<Eigen::Lower>().rankUpdate(f.transpose());
      s.xy.noalias() += f.transpose() * y;
      s.yy += y.colwise().squaredNorm().transpose();
    }
    s.g = s.g.selfadjointView<Eigen::Lower>();
    s.rows = idx.size();
    out->total.g += s.g;
    out->total.xy += s.xy;
    out->total.yy += s.yy;
    out->total.rows += s.rows;
  }
  out->scale = VectorXd::Ones(p);
  for (int j = 1; j < p; ++j) {
    const double ms = out->total.g(j, j) / static_cast<double>(rows);
    out->scale(j) = ms > 0 ? 1.0 / std::sqrt(ms) : 1.0;
  }
  out->train.clear();
  out->train.reserve(out->stats.size());
  for (const FoldStats& s : out->stats) out->train.push_back(Subtract(out->total, s));
}

/// The model trained without fold k (temperature terms in the per-channel form).
Solved SolveWithoutFold(const Layout& layout, const Folds& folds, const std::vector<int>& cols,
                        ModelKind kind, double lambda, int k) {
  const FoldStats& train = folds.train[static_cast<std::size_t>(k)];
  Solved s = Solve(train, cols, folds.scale, lambda);
  if (UsesTemp(kind)) ProjectTemperature(layout, cols, train, s.beta, nullptr, nullptr);
  return s;
}

/// Fold k's share of the score: its held-out rows' mean over axes of (error / rated)², times the
/// fraction of the validation units it holds (each unit counts once, whatever its row count).
double FoldShare(const Eigen::Matrix<double, 6, 1>& sse, const std::array<double, 6>& rated,
                 const Folds& folds, int k) {
  const std::size_t rows = folds.rows[static_cast<std::size_t>(k)].size();
  if (rows == 0) return 0.0;
  double share = 0.0;
  for (std::size_t a = 0; a < 6; ++a) {
    share +=
        sse(static_cast<Eigen::Index>(a)) / static_cast<double>(rows) / std::pow(rated[a], 2) / 6.0;
  }
  return share * folds.unit_fraction[static_cast<std::size_t>(k)];
}

/// Cross-validates every candidate model and ridge strength into res->candidates.
void CrossValidate(const Layout& layout, const Folds& folds, const std::vector<ModelKind>& models,
                   const FitOptions& options, std::size_t rows, FitResult* res) {
  for (ModelKind kind : models) {
    const std::vector<int> cols = layout.Columns(kind);
    if (cols.size() * 2 > rows) continue;  // not enough rows for this model
    for (double lambda : options.lambdas) {
      CandidateScore c;
      Eigen::Matrix<double, 6, 1> sse = Eigen::Matrix<double, 6, 1>::Zero();
      for (int k = 0; k < folds.k; ++k) {
        const Solved s = SolveWithoutFold(layout, folds, cols, kind, lambda, k);
        const Eigen::Matrix<double, 6, 1> fold_sse =
            HeldOutSse(folds.stats[static_cast<std::size_t>(k)], cols, s.beta);
        c.fold_score.push_back(FoldShare(fold_sse, res->rated, folds, k));
        c.score += c.fold_score.back();
        sse += fold_sse;
      }
      c.kind = kind;
      c.lambda = lambda;
      c.features = static_cast<int>(cols.size());
      for (std::size_t a = 0; a < 6; ++a) {
        c.rms_si[a] = std::sqrt(sse(static_cast<Eigen::Index>(a)) / static_cast<double>(rows));
      }
      if (std::isfinite(c.score)) res->candidates.push_back(c);
    }
  }
}

/// Held-out residuals of the chosen model, row by row, and their 95th percentile per axis.
void HeldOutResiduals(const FeatureBuilder& builder, const Layout& layout, const Folds& folds,
                      const Folds& train, const std::vector<int>& cols, std::size_t rows,
                      FitResult* res) {
  res->heldout_residual.resize(static_cast<Eigen::Index>(rows), 6);
  MatrixXd f;
  MatrixXd y;
  for (int k = 0; k < folds.k; ++k) {
    const Solved s = SolveWithoutFold(layout, train, cols, res->kind, res->lambda, k);
    const auto& idx = folds.rows[static_cast<std::size_t>(k)];
    for (std::size_t b = 0; b < idx.size(); b += kChunk) {
      const std::size_t e = std::min(idx.size(), b + kChunk);
      builder.Fill(idx, b, e, f, y);
      MatrixXd fc(f.rows(), static_cast<Eigen::Index>(cols.size()));
      for (std::size_t j = 0; j < cols.size(); ++j)
        fc.col(static_cast<Eigen::Index>(j)) = f.col(cols[j]);
      const MatrixXd r = fc * s.beta - y;
      for (Eigen::Index i = 0; i < r.rows(); ++i) {
        res->heldout_residual.row(static_cast<Eigen::Index>(idx[b + static_cast<std::size_t>(i)])) =
            r.row(i);
      }
    }
  }
  for (int a = 0; a < 6; ++a) {
    std::vector<double> v(rows);
    for (std::size_t i = 0; i < rows; ++i) {
      v[i] = std::fabs(res->heldout_residual(static_cast<Eigen::Index>(i), a));
    }
    res->heldout_p95_si[static_cast<std::size_t>(a)] = Percentile95(std::move(v));
  }
}

/// Held-out scores per unit (block or group), worst first.
std::vector<BlockScore> ScoreUnits(const RigData& d, const std::vector<int>& unit, int units,
                                   const FitResult& fit) {
  const std::size_t rows = unit.size();
  std::vector<BlockScore> scores(static_cast<std::size_t>(units));
  std::vector<double> block_ss(static_cast<std::size_t>(units), 0.0);
  for (std::size_t i = 0; i < rows; ++i) {
    BlockScore& b = scores[static_cast<std::size_t>(unit[i])];
    if (b.rows == 0) b.t_start_s = d.t_s[i];
    b.t_end_s = d.t_s[i];
    ++b.rows;
    for (std::size_t a = 0; a < 6; ++a) {
      const auto ii = static_cast<Eigen::Index>(i);
      const auto aa = static_cast<Eigen::Index>(a);
      b.mean_wrench[a] += d.wrench(ii, aa);
      block_ss[static_cast<std::size_t>(unit[i])] +=
          std::pow(fit.heldout_residual(ii, aa) / fit.rated[a] * 100.0, 2) / 6.0;
    }
  }
  for (std::size_t bi = 0; bi < scores.size(); ++bi) {
    BlockScore& b = scores[bi];
    b.block = static_cast<int>(bi);
    if (b.rows > 0) {
      for (double& w : b.mean_wrench) w /= static_cast<double>(b.rows);
      b.rms_pct = std::sqrt(block_ss[bi] / static_cast<double>(b.rows));
    }
  }
  std::sort(scores.begin(), scores.end(),
            [](const BlockScore& a, const BlockScore& b) { return a.rms_pct > b.rms_pct; });
  return scores;
}

/// Blocks whose held-out RMS lies more than 3.5 robust standard deviations (1.4826 × MAD) above
/// the median of all blocks: recorded badly (a slipped mass, a wrong reference) or a load the
/// model cannot reach. Their rows get the weight limit / RMS (Huber); others 1.
std::vector<double> SuspectWeights(const RigData& d, const std::vector<BlockScore>& blocks,
                                   std::vector<int>* suspects) {
  std::vector<double> rms;
  for (const BlockScore& b : blocks) rms.push_back(b.rms_pct);
  std::vector<double> weight;
  if (rms.size() < 5) return weight;
  std::vector<double> v = rms;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  const double median = v[v.size() / 2];
  for (double& x : v) x = std::fabs(x - median);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  const double limit = median + 3.5 * 1.4826 * v[v.size() / 2];
  std::vector<double> block_weight(static_cast<std::size_t>(d.block_count), 1.0);
  for (const BlockScore& b : blocks) {
    if (b.rms_pct > limit && limit > 0) {
      suspects->push_back(b.block);
      block_weight[static_cast<std::size_t>(b.block)] = limit / b.rms_pct;
    }
  }
  if (suspects->empty()) return weight;
  weight.resize(d.block.size());
  for (std::size_t i = 0; i < d.block.size(); ++i)
    weight[i] = block_weight[static_cast<std::size_t>(d.block[i])];
  return weight;
}

/// The chosen model trained on the weighted folds and tested on the unweighted held-out rows,
/// scored as a candidate (with its per-fold shares).
CandidateScore WeightedScore(const Layout& layout, const Folds& folds, const Folds& weighted,
                             const std::vector<int>& cols, const FitResult& res) {
  CandidateScore c;
  c.kind = res.kind;
  c.lambda = res.lambda;
  c.features = static_cast<int>(cols.size());
  for (int k = 0; k < folds.k; ++k) {
    const Solved s = SolveWithoutFold(layout, weighted, cols, res.kind, res.lambda, k);
    c.fold_score.push_back(FoldShare(
        HeldOutSse(folds.stats[static_cast<std::size_t>(k)], cols, s.beta), res.rated, folds, k));
    c.score += c.fold_score.back();
  }
  return c;
}

/// Training residual σ, the parameter part of the uncertainty and the design's condition number.
void FinalFitQuality(const Folds& folds, const std::vector<int>& cols, const Solved& s,
                     std::size_t rows, FitResult* res) {
  const Eigen::Matrix<double, 6, 1> sse = HeldOutSse(folds.total, cols, s.beta);
  const double dof = std::max(1.0, static_cast<double>(rows) - s.p_eff);
  for (std::size_t a = 0; a < 6; ++a) {
    const double sigma = std::sqrt(sse(static_cast<Eigen::Index>(a)) / dof);
    res->residual_sigma_si[a] = sigma;
    res->fit_uncertainty_si[a] = sigma * std::sqrt(s.p_eff / static_cast<double>(rows));
  }
  const auto q = static_cast<Eigen::Index>(cols.size());
  MatrixXd g(q, q);
  for (Eigen::Index i = 0; i < q; ++i) {
    for (Eigen::Index j = 0; j < q; ++j) {
      const int ci = cols[static_cast<std::size_t>(i)];
      const int cj = cols[static_cast<std::size_t>(j)];
      g(i, j) =
          folds.total.g(ci, cj) * folds.scale(ci) * folds.scale(cj) / static_cast<double>(rows);
    }
  }
  res->design_condition = GramCondition(g);
}

/// Into the calibration's form: undo the centring (intercept = μ_y + β0 − Σ β_j μ_j).
void ToCalibration(const Layout& layout, const Folds& folds, const Reference& ref,
                   const std::vector<int>& cols, const Solved& s, const VectorXd& alpha,
                   const VectorXd& gamma, FitResult* res) {
  const int n = layout.n;
  fw::FloatCalibration& cal = res->cal;
  cal.channel_count = static_cast<std::uint8_t>(n);
  std::map<int, Eigen::Index> pos;
  for (std::size_t i = 0; i < cols.size(); ++i) pos[cols[i]] = static_cast<Eigen::Index>(i);
  for (int a = 0; a < 6; ++a) {
    double c0 = folds.mu_y(a) + s.beta(0, a);
    for (std::size_t i = 1; i < cols.size(); ++i)
      c0 -= s.beta(static_cast<Eigen::Index>(i), a) * folds.mu(cols[i]);
    cal.bias[static_cast<std::size_t>(a)] = c0;
    for (int c = 0; c < n; ++c) {
      cal.matrix[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)] =
          s.beta(pos.at(1 + c), a);
    }
  }
  for (int c = 0; c < n; ++c) cal.offset_mvv[static_cast<std::size_t>(c)] = ref.offset(c);
  if (UsesQuad(res->kind)) {
    std::size_t used = 0;
    for (std::size_t k = 0; k < layout.pairs.size(); ++k) {
      const auto it = pos.find(layout.quad_start + static_cast<int>(k));
      if (it == pos.end()) continue;  // a product the model does not use
      cal.products[used] = fw::ProductTerm{static_cast<std::uint8_t>(layout.pairs[k].first),
                                           static_cast<std::uint8_t>(layout.pairs[k].second)};
      for (int a = 0; a < 6; ++a) {
        cal.product_matrix[static_cast<std::size_t>(a)][used] = s.beta(it->second, a);
      }
      ++used;
    }
    cal.product_count = static_cast<std::uint8_t>(used);
  }
  if (UsesTemp(res->kind)) {
    cal.temperature_compensated = true;
    cal.temp_ref_c = ref.t_ref;
    cal.temp_min_c = ref.t_min;
    cal.temp_max_c = ref.t_max;
    for (int c = 0; c < n; ++c) {
      cal.bias_slope_mvv_per_c[static_cast<std::size_t>(c)] = alpha(c);
      cal.gain_slope_per_c[static_cast<std::size_t>(c)] = gamma(c);
    }
  }
}

}  // namespace

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
  res.rated = RatedScale(d, options);
  const std::vector<ModelKind> models = CandidateModels(d, options);
  const bool want_quad = std::any_of(models.begin(), models.end(), UsesQuad);
  const bool want_temp = std::any_of(models.begin(), models.end(), UsesTemp);
  // With neither requested, the layout holds only what is needed (speed on large inputs).
  Layout layout(n, want_temp);
  if (!want_quad) {
    layout.pairs.clear();
    layout.total = layout.quad_start;
  }
  const Reference ref = FindReference(d, res.rated, want_temp);

  Folds folds;
  res.validation = AssignFolds(d, options, want_temp, &folds);
  res.folds = folds.k;
  CentreFeatures(d, layout, ref, &folds);
  const FeatureBuilder builder(d, layout, ref.offset, ref.t_ref, folds.mu, folds.mu_y);
  AccumulateFolds(builder, layout.total, rows, &folds);

  CrossValidate(layout, folds, models, options, rows, &res);
  if (res.candidates.empty()) throw std::invalid_argument(d.path + ": too few rows for any model");
  const CandidateScore chosen =
      res.candidates[ChooseOneStandardError(res.candidates, &res.over_simplest, &res.challenger)];
  res.kind = chosen.kind;
  res.lambda = chosen.lambda;
  res.lambda_at_bound =
      chosen.lambda > 0 &&
      chosen.lambda >= *std::max_element(options.lambdas.begin(), options.lambdas.end());
  res.heldout_rms_si = chosen.rms_si;
  const std::vector<int> cols = layout.Columns(res.kind);
  HeldOutResiduals(builder, layout, folds, folds, cols, rows, &res);
  res.blocks = ScoreUnits(d, d.block, d.block_count, res);
  // Robust variant: suspect blocks down-weighted; kept only when it validates better.
  const std::vector<double> weight = SuspectWeights(d, res.blocks, &res.suspect_blocks);
  Folds weighted;
  if (!weight.empty()) {
    weighted.k = folds.k;
    weighted.rows = folds.rows;
    weighted.unit_fraction = folds.unit_fraction;
    weighted.mu = folds.mu;
    weighted.mu_y = folds.mu_y;
    AccumulateFolds(builder, layout.total, rows, &weighted, &weight);
    weighted.scale = folds.scale;
    const CandidateScore robust = WeightedScore(layout, folds, weighted, cols, res);
    res.robust_margin = CompareCandidates(chosen, robust);
    res.robust_margin.complex += " down-weighted";
    res.plain_score = chosen.score;
    res.robust_score = robust.score;
    res.robust = res.robust_margin.Significant();
    if (res.robust) {
      HeldOutResiduals(builder, layout, folds, weighted, cols, rows, &res);
      for (std::size_t a = 0; a < 6; ++a) {
        res.heldout_rms_si[a] =
            std::sqrt(res.heldout_residual.col(static_cast<Eigen::Index>(a)).squaredNorm() / rows);
      }
      res.blocks = ScoreUnits(d, d.block, d.block_count, res);
    }
  }
  const Folds& train = res.robust ? weighted : folds;
  if (d.group.size() == d.block.size() && d.group_count > 0)
    res.groups = ScoreUnits(d, d.group, d.group_count, res);

  // Final fit on all rows.
  Solved s = Solve(train.total, cols, folds.scale, res.lambda);
  VectorXd alpha;
  VectorXd gamma;
  if (UsesTemp(res.kind)) ProjectTemperature(layout, cols, train.total, s.beta, &alpha, &gamma);
  FinalFitQuality(folds, cols, s, rows, &res);
  res.load_condition = LoadSetCondition(d.wrench, res.rated);
  ToCalibration(layout, folds, ref, cols, s, alpha, gamma, &res);
  return res;
}

}  // namespace ftstack::cal
