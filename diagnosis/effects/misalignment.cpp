// misalignment: the sensor frame rotated against the reference wrench's frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/engine/training_rows.hpp"

namespace ftstack::diag::fx {

namespace {

/// The largest rotation searched: a sensor mounted 20° off is a wrong axis, not a misalignment.
constexpr double kMaxAngleDeg = 20.0;

std::vector<ParamSpec> MisalignmentSpecs(const Context& /*cx*/) {
  return {{.key = "angle_deg",
           .lo = -kMaxAngleDeg,
           .hi = kMaxAngleDeg,
           .lo_what = "20° (a wrong axis, not a misalignment)",
           .hi_what = "20° (a wrong axis, not a misalignment)",
           .unit = "deg",
           .scale = ParamScale::kLinear,
           .grid_points = 81,
           .golden_steps = 40}};
}

using Vec6 = Eigen::Matrix<double, 6, 1>;

/// Sensor frame rotated by +θ about an axis: it reads Rᵀ·F and Rᵀ·M, so the change of the wrench
/// is exactly (cos θ − 1)·U + sin θ·V with U, V linear in the wrench (row i of `w`); the residual
/// is S times that.
void RotationBasis(const Eigen::MatrixXf& w, int axis, int i, Vec6* u, Vec6* v) {
  const int a1 = (axis + 1) % 3;
  const int a2 = (axis + 2) % 3;
  u->setZero();
  v->setZero();
  for (int off : {0, 3}) {
    (*u)(off + a1) = w(i, off + a1);
    (*u)(off + a2) = w(i, off + a2);
    (*v)(off + a1) = w(i, off + a2);
    (*v)(off + a2) = -w(i, off + a1);
  }
}

/// Weighted sums over the training rows that make the fit's SSE a closed form in θ.
struct RotationSums {
  double rr = 0, r1 = 0, r2 = 0, q11 = 0, q22 = 0, q12 = 0;
  [[nodiscard]] double Sse(double th) const {
    const double cm = std::cos(th) - 1.0;
    const double sn = std::sin(th);
    return rr - 2 * cm * r1 - 2 * sn * r2 + cm * cm * q11 + sn * sn * q22 + 2 * cm * sn * q12;
  }
};

RotationSums SumRotation(const Context& cx, const Series& target, int axis) {
  RotationSums m;
  Vec6 u;
  Vec6 v;
  ForTrainingRows(cx, 0, cx.n, [&](int i) {
    RotationBasis(cx.data->wrench, axis, i, &u, &v);
    for (int c = 0; c < cx.nc; ++c) {
      const double p1 = cx.sens.row(c).dot(u);
      const double p2 = cx.sens.row(c).dot(v);
      const double r = target(i, c);
      const double wc = cx.weight(c);
      m.rr += wc * r * r;
      m.r1 += wc * r * p1;
      m.r2 += wc * r * p2;
      m.q11 += wc * p1 * p1;
      m.q22 += wc * p2 * p2;
      m.q12 += wc * p1 * p2;
    }
  });
  return m;
}

}  // namespace

std::optional<EffectFit> FitMisalignment(const Context& cx, const Series& target) {
  if (!cx.data->has_wrench()) return std::nullopt;
  const Eigen::MatrixXf& w = cx.data->wrench;
  auto uv = [&](int axis, int i, Vec6* u, Vec6* v) { RotationBasis(w, axis, i, u, v); };
  EffectFit best;
  double best_sse = std::numeric_limits<double>::infinity();
  const double lim = kMaxAngleDeg * M_PI / 180.0;
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const RotationSums sums = SumRotation(cx, target, axis);
    auto sse = [&](double th) { return sums.Sse(th); };
    Vec6 u;
    Vec6 v;
    // The engine searches in radians (the profile's own coordinate), the spec says degrees.
    ParamSpec rad = MisalignmentSpecs(cx)[0];
    rad.lo = -lim;
    rad.hi = lim;
    SolveOptions opt{.sigma_step = 1e-5};
    for (int j = -40; j <= 40; ++j) opt.start.push_back(lim * j / 40.0);
    const SolvedParam s = SolveParameter(rad, sse, opt);
    const double th = s.value;
    const double fmin = s.objective;
    if (fmin < best_sse) {
      best_sse = fmin;
      EffectFit e;
      e.name = "misalignment";
      e.n_params = 1;
      e.train_sse_w = fmin;
      e.pred.resize(cx.n, cx.nc);
      const double cm = std::cos(th) - 1.0;
      const double sn = std::sin(th);
      for (int i = 0; i < cx.n; ++i) {
        uv(axis, i, &u, &v);
        const Eigen::Matrix<double, 6, 1> dw = cm * u + sn * v;
        for (int c = 0; c < cx.nc; ++c) e.pred(i, c) = cx.sens.row(c).dot(dw);
      }
      e.params["axis"] = names[axis];
      e.params["angle_deg"] = th * 180.0 / M_PI;
      e.sigma["angle_deg"] = JsonNum(s.sigma * 180.0 / M_PI);
      best = std::move(e);
    }
  }
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  best.evidence =
      Fmt("cross-talk on %d channels is explained by one rotation of the sensor frame, %.2f° about "
          "%s (b%d r = %.2f)",
          static_cast<int>(best.channels.size()), best.params["angle_deg"].get<double>(),
          best.params["axis"].get<std::string>().c_str(), c, RowCorr(cx, target, best.pred, c));
  return best;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec MisalignmentPlugin() {
  return {.kind = EffectKind::kMisalignment,
          .fit = &fx::FitMisalignment,
          .ranges = &fx::MisalignmentSpecs};
}

}  // namespace ftstack::diag
