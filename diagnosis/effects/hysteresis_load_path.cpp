// hysteresis in the load path: rate-independent operators on each reference wrench
// axis, seen by the bridges through the sensor's own sensitivity (cx.sens) — one operator of a
// searched width, or a Prandtl–Ishlinskii sum of play operators of fixed widths (general shape).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::diag {
namespace {

using Mat = Eigen::MatrixXd;
constexpr const auto& kAxis = kWrenchAxisNames;  // measurement/wrench.hpp
/// Play widths of the Prandtl–Ishlinskii variant, as fractions of each axis's load range.
constexpr std::array<double, 5> kPiWidths = {0.03, 0.08, 0.2, 0.5, 1.2};

/// The operators of one variant: `per_axis` features per excited axis, stepped row by row.
struct AxisOperators {
  std::vector<int> axes;       ///< excited wrench axes
  std::vector<double> widths;  ///< per feature: full play width in the axis's unit (0 = Dahl)
  std::vector<double> dahl;    ///< per feature: Dahl width (when widths is 0)
  std::vector<double> up;      ///< per feature: relay thresholds (when not empty)
  std::vector<double> down;
  int per_axis = 1;
  std::vector<double> state;
  [[nodiscard]] int p() const { return static_cast<int>(axes.size()) * per_axis; }
  void Reset() { state.assign(static_cast<std::size_t>(p()), 0.0); }
  /// Features of row i (restart: operators start again at rest at this row's load).
  void Step(const Eigen::MatrixXf& w, int i, bool restart, double* z) {
    for (std::size_t a = 0; a < axes.size(); ++a) {
      const double x = w(i, axes[a]);
      const double dx = i > 0 && !restart ? x - w(i - 1, axes[a]) : 0.0;
      for (int j = 0; j < per_axis; ++j) {
        const std::size_t f = a * static_cast<std::size_t>(per_axis) + static_cast<std::size_t>(j);
        double& s = state[f];
        if (!up.empty()) {  // relay: unknown (0) until a threshold is first reached
          if (i == 0 || restart) s = 0.0;
          if (x >= up[f]) s = 1.0;
          if (x <= down[f]) s = -1.0;
          z[f] = s;
        } else if (widths[f] > 0) {
          const double h = 0.5 * widths[f];
          s = i == 0 || restart ? x : std::clamp(s, x - h, x + h);
          z[f] = (s - x) / h;
        } else {
          if (i == 0 || restart) s = 0.0;
          if (dx != 0.0) {
            const double t = dx > 0 ? 1.0 : -1.0;
            s = t + (s - t) * std::exp(-std::fabs(dx) / dahl[f]);
          }
          z[f] = s;
        }
      }
    }
  }
};

/// The training rows grouped in runs of one wrench: rate-independent operators change state only
/// when the load moves, so every statistic is accumulated once per run (a hold of 600 rows costs
/// one step). Per run: its first row, the (every stride-th) training rows' count, Σ SᵀW·y (6) and
/// Σ yᵀW·y.
struct Runs {
  std::vector<int> first;
  std::vector<double> count;
  Mat swy;  ///< runs × 6
  double yy = 0.0;
  double rows = 0.0;
  int stride = 1;
};

Runs MakeRuns(const Context& cx, const Series& target, int stride) {
  const Eigen::MatrixXf& w = cx.data->wrench;
  Runs r;
  r.stride = stride;
  std::vector<double> acc;
  ForRowsWithTraining(cx, 0, cx.n, [&](int i, bool train) {
    const bool restart = !cx.restart.empty() && cx.restart[static_cast<std::size_t>(i)] != 0;
    if (i == 0 || restart || w.row(i) != w.row(i - 1)) {
      r.first.push_back(i);
      r.count.push_back(0.0);
      acc.resize(acc.size() + 6, 0.0);
    }
    if (!train || i % stride != 0) return;
    double* sw = acc.data() + acc.size() - 6;
    for (int c = 0; c < cx.nc; ++c) {
      const double wy = cx.weight(c) * target(i, c);
      r.yy += wy * target(i, c);
      for (int a = 0; a < 6; ++a) sw[a] += cx.sens(c, a) * wy;
    }
    r.count.back() += 1.0;
    r.rows += 1.0;
  });
  r.swy = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>>(
      acc.data(), static_cast<Eigen::Index>(r.first.size()), 6);
  return r;
}

/// Whitened least squares of target ≈ S · (β_axis · z) over the runs' training rows:
/// XᵀWX = Σ G(k,l)·z_k z_l with G = SᵀWS, so a run costs p² and not N·p².
struct AxisFit {
  Eigen::VectorXd beta;
  Mat cov_unit;
  double sse_w = 0.0;
  double rows = 0.0;
};

AxisFit Solve(const Context& cx, const Runs& runs, AxisOperators ops) {
  const DiagData& d = *cx.data;
  const int p = ops.p();
  const int na = static_cast<int>(ops.axes.size());
  Mat s_ax(cx.nc, na);
  for (int a = 0; a < na; ++a) s_ax.col(a) = cx.sens.col(ops.axes[static_cast<std::size_t>(a)]);
  const Mat g = s_ax.transpose() * cx.weight.asDiagonal() * s_ax;
  Mat zz = Mat::Zero(p, p);
  Eigen::VectorXd zy = Eigen::VectorXd::Zero(p);
  std::vector<double> z(static_cast<std::size_t>(p));
  ops.Reset();
  for (std::size_t k = 0; k < runs.first.size(); ++k) {
    const int i = runs.first[k];
    const bool restart = !cx.restart.empty() && cx.restart[static_cast<std::size_t>(i)] != 0;
    ops.Step(d.wrench, i, restart, z.data());
    const double m = runs.count[k];
    if (m == 0.0) continue;
    // Lower triangle by hand (a small dynamic rankUpdate costs more); relays are often 0.
    double* zz_data = zz.data();
    for (int f = 0; f < p; ++f) {
      const double zf = m * z[static_cast<std::size_t>(f)];
      if (zf == 0.0) continue;
      double* col = zz_data + static_cast<std::ptrdiff_t>(f) * p;
      for (int h = f; h < p; ++h) col[h] += zf * z[static_cast<std::size_t>(h)];
      zy(f) += z[static_cast<std::size_t>(f)] *
               runs.swy(static_cast<Eigen::Index>(k),
                        ops.axes[static_cast<std::size_t>(f / ops.per_axis)]);
    }
  }
  zz = zz.selfadjointView<Eigen::Lower>();
  Mat xtx(p, p);
  for (int f = 0; f < p; ++f) {
    for (int h = 0; h < p; ++h) xtx(f, h) = g(f / ops.per_axis, h / ops.per_axis) * zz(f, h);
  }
  const Mat ridge = xtx + 1e-12 * xtx.diagonal().maxCoeff() * Mat::Identity(p, p);
  AxisFit out;
  out.cov_unit = ridge.ldlt().solve(Mat::Identity(p, p));
  out.beta = out.cov_unit * zy;
  out.sse_w =
      std::max(0.0, runs.yy - 2.0 * out.beta.dot(zy) + out.beta.dot(xtx * out.beta)) * runs.stride;
  out.rows = runs.rows * runs.stride;
  return out;
}

Series Predict(const Context& cx, const Runs& runs, AxisOperators ops,
               const Eigen::VectorXd& beta) {
  const int p = ops.p();
  Series pred(cx.n, cx.nc);
  std::vector<double> z(static_cast<std::size_t>(p));
  Eigen::VectorXd dw(6);
  ops.Reset();
  for (std::size_t k = 0; k < runs.first.size(); ++k) {
    const int i0 = runs.first[k];
    const int i1 = k + 1 < runs.first.size() ? runs.first[k + 1] : cx.n;
    const bool restart = !cx.restart.empty() && cx.restart[static_cast<std::size_t>(i0)] != 0;
    ops.Step(cx.data->wrench, i0, restart, z.data());
    dw.setZero();
    for (int f = 0; f < p; ++f)
      dw(ops.axes[static_cast<std::size_t>(f / ops.per_axis)]) +=
          beta(f) * z[static_cast<std::size_t>(f)];
    const Eigen::RowVectorXd row = (cx.sens * dw).transpose();
    for (int i = i0; i < i1; ++i) pred.row(i) = row.cast<float>();
  }
  return pred;
}

AxisOperators OneOperator(const std::vector<int>& axes, const Eigen::VectorXd& range, double frac,
                          bool play) {
  AxisOperators o;
  o.axes = axes;
  for (int a : axes) {
    o.widths.push_back(play ? frac * range(a) : 0.0);
    o.dahl.push_back(frac * range(a));
  }
  return o;
}

/// Preisach relays on each axis: every pair of 8 levels (quantiles of the axis's load).
AxisOperators AxisRelays(const DiagData& d, const std::vector<int>& axes) {
  constexpr int kLevels = 8;
  AxisOperators o;
  o.axes = axes;
  o.per_axis = kLevels * (kLevels - 1) / 2;
  for (int a : axes) {
    std::vector<double> v(d.wrench.col(a).data(), d.wrench.col(a).data() + d.wrench.rows());
    std::array<double, kLevels> level{};
    MidQuantiles(&v, kLevels, level.data());
    for (int lo = 0; lo < kLevels; ++lo) {
      for (int hi = lo + 1; hi < kLevels; ++hi) {
        o.down.push_back(level[static_cast<std::size_t>(lo)]);
        o.up.push_back(level[static_cast<std::size_t>(hi)]);
        o.widths.push_back(0.0);
        o.dahl.push_back(1.0);
      }
    }
  }
  return o;
}

/// The operator family chosen for the loop, with what the report says of it.
struct OperatorChoice {
  AxisOperators ops;
  double travel_fraction = 0.0;  // the single-operator width; unused for weighted families
  bool weights_only = false;     // Prandtl–Ishlinskii or Preisach: no width parameter
  std::string variant;
};

/// One Dahl or play operator per axis (width searched), then weighted plays, then relays: the
/// family with the lowest penalised cost wins.
OperatorChoice ChooseOperators(const Context& cx, const Runs& runs, const std::vector<int>& axes,
                               const Eigen::VectorXd& range, double pen) {
  const ParamSpec width = fx::HysteresisSpecs(cx)[0];
  OperatorChoice best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (bool play : {false, true}) {
    const auto f = [&](double v) {
      return Solve(cx, runs, OneOperator(axes, range, std::exp(v), play)).sse_w;
    };
    const double lw = SolveParameter(width, f, {.sigma_step = 0.0}).coord;
    AxisOperators o = OneOperator(axes, range, std::exp(lw), play);
    const double cost = Solve(cx, runs, o).sse_w + (o.p() + 1) * pen;
    if (cost < best_cost) {
      best_cost = cost;
      best = {o, std::exp(lw), false,
              play ? "play (backlash) operator on each wrench axis, through the sensitivity"
                   : "Dahl operator on each wrench axis, through the sensitivity"};
    }
  }
  // Prandtl–Ishlinskii: plays of fixed widths per axis, weights free (general loop shape).
  AxisOperators pi;
  pi.axes = axes;
  pi.per_axis = static_cast<int>(kPiWidths.size());
  for (int a : axes) {
    for (double wf : kPiWidths) {
      pi.widths.push_back(wf * range(a));
      pi.dahl.push_back(wf * range(a));
    }
  }
  const double pi_cost = Solve(cx, runs, pi).sse_w + pi.p() * pen;
  if (pi_cost < best_cost) {
    best_cost = pi_cost;
    best = {pi, 0.0, true,
            "Prandtl–Ishlinskii: weighted plays of 5 widths on each wrench axis, through the "
            "sensitivity"};
  }
  // Preisach: relays on a grid of each axis's load levels (contains loops of any shape there).
  const AxisOperators relays = AxisRelays(*cx.data, axes);
  if (cx.n > 20 * relays.p() && Solve(cx, runs, relays).sse_w + relays.p() * pen < best_cost) {
    best = {relays, 0.0, true,
            "Preisach: weighted sum of 28 relays (thresholds on 8 quantiles of the axis's load) on "
            "each wrench axis, through the sensitivity"};
  }
  return best;
}

/// Loop half-height per axis (N or N·m: the sum of the axis's operator weights) and its σ; the
/// axis with the largest loop relative to its range.
int LoopHalfHeights(const AxisOperators& ops, const AxisFit& fit, const Eigen::VectorXd& range,
                    EffectFit* e) {
  const double var = fit.rows > ops.p() ? fit.sse_w / (fit.rows - ops.p()) : 0.0;
  double top = 0.0;
  int top_axis = ops.axes.front();
  nlohmann::json half = nlohmann::json::object();
  nlohmann::json half_sigma = nlohmann::json::object();
  for (std::size_t a = 0; a < ops.axes.size(); ++a) {
    double h = 0.0;
    double s2 = 0.0;
    for (int j = 0; j < ops.per_axis; ++j) {
      const int f = static_cast<int>(a) * ops.per_axis + j;
      h += fit.beta(f);
      for (int j2 = 0; j2 < ops.per_axis; ++j2) {
        s2 += fit.cov_unit(f, static_cast<int>(a) * ops.per_axis + j2) * var;
      }
    }
    half[kAxis[ops.axes[a]]] = h;
    half_sigma[kAxis[ops.axes[a]]] = std::sqrt(std::max(0.0, s2));
    const double rel = std::fabs(h) / range(ops.axes[a]);
    if (rel > top) {
      top = rel;
      top_axis = ops.axes[a];
    }
  }
  e->params["loop_half_height"] = half;  // N for forces, N·m for moments
  e->sigma["loop_half_height"] = half_sigma;
  return top_axis;
}

}  // namespace

std::optional<EffectFit> FitHysteresisAxes(const Context& cx, const Series& target) {
  const DiagData& d = *cx.data;
  if (!d.has_wrench() || cx.sens.cols() != 6) return std::nullopt;
  Eigen::VectorXd range(6);
  std::vector<int> axes;
  for (int k = 0; k < 6; ++k) {
    range(k) = d.wrench.col(k).maxCoeff() - d.wrench.col(k).minCoeff();
    if (range(k) > 0 && cx.sens.col(k).norm() > 0) axes.push_back(k);
  }
  if (axes.empty()) return std::nullopt;
  const Runs runs = MakeRuns(cx, target, cx.search_stride);
  const double pen = std::log(std::max(2.0, static_cast<double>(cx.n_train) * cx.nc));
  const OperatorChoice best = ChooseOperators(cx, runs, axes, range, pen);
  // Final weights from every row_step-th training row too (the operators' states change only at
  // load reversals and threshold crossings, so little is lost on long records); predictions on all.
  const AxisFit fit = Solve(cx, runs, best.ops);
  EffectFit e;
  e.name = "hysteresis";
  e.variant = best.variant;
  e.n_params = best.ops.p() + (best.weights_only ? 0 : 1);
  e.pred = Predict(cx, runs, best.ops, fit.beta);
  e.train_sse_w = fit.sse_w;
  const int top_axis = LoopHalfHeights(best.ops, fit, range, &e);
  if (!best.weights_only) e.params["travel_fraction"] = best.travel_fraction;
  e.evidence = fx::ReversalEvidence(cx, &e) +
               fx::Fmt(", constant during holds: a loop of %.3g %s on %s",
                       2.0 * std::fabs(e.params["loop_half_height"][kAxis[top_axis]].get<double>()),
                       top_axis < 3 ? "N" : "N·m", kAxis[top_axis]);
  return e;
}

}  // namespace ftstack::diag
