// zero_drift: the offset of each bridge moving in time: a smooth function (hat splines, knots
// chosen by BIC) or, variant "steps at load changes", a level per stretch between load changes
// (the zero shifts when a weight is hung or removed by hand), whichever has the lower training BIC.
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

/// The smooth variant's fit: k hat-spline intervals, per channel coefficients, training SSE.
struct SmoothDrift {
  int k = 0;
  std::vector<Vec> beta;
  double sse_w = 0.0;
  bool at_top = false;  ///< the BIC still fell at the finest knot grid the record allows
};

/// Smooth functions of time per channel (hat splines), knots chosen by BIC on training rows.
std::optional<SmoothDrift> FitSmoothDrift(const Context& cx, const Series& target) {
  const double duration = cx.data->t_s.back() - cx.data->t_s.front();
  // Per channel hat-spline fit with k intervals on every row_step-th training row.
  auto fit_k = [&](int k, int row_step, std::vector<Vec>* beta) {
    const HatBasis hb = MakeHat(cx, k);
    double sse_w = 0.0;
    beta->clear();
    for (int c = 0; c < cx.nc; ++c) {
      NormalEq ne(k + 1);
      ForTrainingRows(
          cx, 0, cx.n,
          [&](int i) {
            int j = 0;
            double fr = 0.0;
            hb.At(cx.data->t_s[static_cast<std::size_t>(i)], &j, &fr);
            const int idx[2] = {j, j + 1};
            const double val[2] = {1.0 - fr, fr};
            ne.AddSparse(idx, val, 2, target(i, c));
          },
          row_step);
      const auto r = ne.Solve();
      sse_w += r.sse * cx.weight(c) * row_step;
      beta->push_back(r.beta);
    }
    return sse_w;
  };
  double best_bic = std::numeric_limits<double>::infinity();
  int best_k = 0;
  int worse = 0;
  int tried = 0;
  int last_k = 0;
  for (int k : {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48}) {
    if (duration / k < 3.0 * cx.block_s) break;
    last_k = k;
    ++tried;
    std::vector<Vec> beta;
    const double sse_w = fit_k(k, cx.search_stride, &beta);
    const double bic = sse_w + cx.nc * (k + 1) * Penalty(cx);
    if (bic < best_bic) {
      best_bic = bic;
      best_k = k;
      worse = 0;
    } else if (++worse >= 2) {
      break;
    }
  }
  if (best_k == 0) return std::nullopt;
  SmoothDrift best;
  best.k = best_k;
  best.sse_w = fit_k(best_k, 1, &best.beta);
  best.at_top = best_k == last_k && tried >= 3;
  return best;
}

/// The smooth variant as an effect: its prediction on every row.
EffectFit SmoothDriftFit(const Context& cx, const SmoothDrift& s) {
  EffectFit fit;
  fit.name = "zero_drift";
  fit.n_params = cx.nc * (s.k + 1);
  fit.train_sse_w = s.sse_w;
  fit.params["knots"] = s.k + 1;
  fit.variant = Fmt("hat spline, %d knots", s.k + 1);
  fit.pred.resize(cx.n, cx.nc);
  const HatBasis hb = MakeHat(cx, s.k);
  for (int i = 0; i < cx.n; ++i) {
    int j = 0;
    double fr = 0.0;
    hb.At(cx.data->t_s[static_cast<std::size_t>(i)], &j, &fr);
    for (int c = 0; c < cx.nc; ++c) {
      const Vec& bc = s.beta[static_cast<std::size_t>(c)];
      fit.pred(i, c) = bc(j) * (1.0 - fr) + bc(j + 1) * fr;
    }
  }
  return fit;
}

/// One past the last row of stretch k (stretches start at `starts`, the last ends at row n).
int StretchEnd(const std::vector<int>& starts, std::size_t k, int n) {
  return k + 1 < starts.size() ? starts[k + 1] : n;
}

/// True when at least half the stretches share their reference load with another stretch (within
/// 2 % of each channel's load range): only then is a level per stretch more than a function of
/// the load (static poses, each held once: the steps would be any static misfit). Whether the
/// levels can also be told from the load's history (the same load reached from the same one) is
/// the identifiability check's question (StatesIdentify), answered in the report.
bool LoadsRecur(const Context& cx, const std::vector<int>& starts) {
  const auto same = [&](std::size_t j, std::size_t k) {
    for (int c = 0; c < cx.nc; ++c) {
      const double tol = 0.02 * cx.load_range(c);
      const auto mid = [&](std::size_t s) { return (starts[s] + StretchEnd(starts, s, cx.n)) / 2; };
      if (std::fabs(cx.load(mid(j), c) - cx.load(mid(k), c)) > tol) return false;
    }
    return true;
  };
  std::size_t recurring = 0;
  for (std::size_t j = 0; j < starts.size(); ++j) {
    for (std::size_t k = 0; k < starts.size(); ++k) {
      if (k != j && same(j, k)) {
        ++recurring;
        break;
      }
    }
  }
  return 2 * recurring >= starts.size();
}

/// The "steps at load changes" variant's fit: a level per stretch and channel, training SSE.
struct HoldLevels {
  std::vector<int> starts;    ///< first row of each stretch
  Eigen::MatrixXf level_mvv;  ///< stretches × channels (in the prediction's precision)
  double sse_w = 0.0;
};

/// A level per channel in each stretch between load changes (fitted on its training rows); nullopt
/// without load changes, when the loads do not recur (LoadsRecur) or with a stretch holding no
/// training row.
std::optional<HoldLevels> FitHoldLevels(const Context& cx, const Series& target) {
  HoldLevels h;
  h.starts = LoadChangeStarts(cx);
  std::vector<int>& starts = h.starts;
  if (starts.empty() || starts.front() != 0) starts.insert(starts.begin(), 0);
  if (starts.size() < 2 || !LoadsRecur(cx, starts)) return std::nullopt;
  h.level_mvv.resize(static_cast<Eigen::Index>(starts.size()), cx.nc);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    for (int c = 0; c < cx.nc; ++c) {
      double sum = 0.0;
      int rows = 0;
      ForTrainingRows(cx, starts[k], StretchEnd(starts, k, cx.n), [&](int i) {
        sum += target(i, c);
        ++rows;
      });
      if (rows == 0) return std::nullopt;
      h.level_mvv(static_cast<Eigen::Index>(k), c) = static_cast<float>(sum / rows);
    }
  }
  for (int c = 0; c < cx.nc; ++c) {
    for (std::size_t k = 0; k < starts.size(); ++k) {
      const float level = h.level_mvv(static_cast<Eigen::Index>(k), c);
      ForTrainingRows(cx, starts[k], StretchEnd(starts, k, cx.n), [&](int i) {
        const double r = target(i, c) - level;
        h.sse_w += r * r * cx.weight(c);
      });
    }
  }
  return h;
}

/// The "steps at load changes" variant as an effect: its levels, their start times, the prediction.
EffectFit HoldLevelsFit(const Context& cx, const HoldLevels& h) {
  EffectFit fit;
  fit.pred.resize(cx.n, cx.nc);
  for (std::size_t k = 0; k < h.starts.size(); ++k) {
    for (int c = 0; c < cx.nc; ++c) {
      const float level = h.level_mvv(static_cast<Eigen::Index>(k), c);
      for (int i = h.starts[k]; i < StretchEnd(h.starts, k, cx.n); ++i) fit.pred(i, c) = level;
    }
  }
  nlohmann::json levels = nlohmann::json::array();
  for (int c = 0; c < cx.nc; ++c) {
    nlohmann::json lc = nlohmann::json::array();
    for (Eigen::Index k = 0; k < h.level_mvv.rows(); ++k) lc.push_back(h.level_mvv(k, c));
    levels.push_back(lc);
  }
  nlohmann::json from = nlohmann::json::array();
  for (const int a : h.starts) from.push_back(cx.data->t_s[static_cast<std::size_t>(a)]);
  fit.params["levels_mvv"] = levels;
  fit.params["level_from_s"] = from;
  fit.name = "zero_drift";
  fit.n_params = cx.nc * static_cast<int>(h.starts.size());
  fit.train_sse_w = h.sse_w;
  fit.params["levels"] = static_cast<int>(h.starts.size());
  fit.variant = kZeroStepsAtChanges;
  return fit;
}

}  // namespace

std::optional<EffectFit> FitZeroDrift(const Context& cx, const Series& target) {
  // Both variants' levels and training SSE first; the prediction only for the one kept.
  const std::optional<SmoothDrift> smooth = FitSmoothDrift(cx, target);
  const std::optional<HoldLevels> steps = FitHoldLevels(cx, target);
  if (!smooth && !steps) return std::nullopt;
  const auto bic = [&](double sse_w, int n_params) { return sse_w + n_params * Penalty(cx); };
  // Steps before a spline whose knot count sits on its bound; else the lower BIC.
  const bool prefer_steps =
      steps && (!smooth || smooth->at_top ||
                bic(steps->sse_w, cx.nc * static_cast<int>(steps->starts.size())) <
                    bic(smooth->sse_w, cx.nc * (smooth->k + 1)));
  EffectFit best = prefer_steps ? HoldLevelsFit(cx, *steps) : SmoothDriftFit(cx, *smooth);
  const bool stepped = best.variant == kZeroStepsAtChanges;
  Vec span(cx.nc);
  for (int c = 0; c < cx.nc; ++c)
    span(c) = best.pred.col(c).maxCoeff() - best.pred.col(c).minCoeff();
  best.params["span_mvv"] = VecJson(span);
  best.channels = ActiveChannels(cx, best.pred);
  const int c = DominantChannel(cx, best.pred);
  std::string temp_note;
  if (!cx.dtemp.empty()) {
    const double rt =
        Correlation(ColD(target, c).data(), cx.dtemp.data(), static_cast<std::size_t>(cx.n));
    temp_note = Fmt("; temperature explains less (r = %.2f)", rt);
  }
  const std::string shape =
      stepped ? Fmt("in steps at the %d load changes", best.params["levels"].get<int>() - 1)
              : Fmt("smoothly in time, r = %.2f with a %d-knot curve",
                    RowCorr(cx, target, best.pred, c), best.params["knots"].get<int>());
  best.evidence = Fmt("offset of b%d wanders by %.3g mV/V (%.1f σ) %s%s", c, span(c),
                      span(c) / cx.sigma(c), shape.c_str(), temp_note.c_str());
  return best;
}

}  // namespace ftstack::diag::fx

namespace ftstack::diag {

EffectSpec ZeroDriftPlugin() {
  return {.kind = EffectKind::kZeroDrift,
          .traits = kTimeBased | kDriftInTime | kRefineOnlyIfBetter,
          .confounders = kConfoundersOfTime,
          .fit = &fx::FitZeroDrift,
          .refine_claim = &RefineWithThermalLag};
}

}  // namespace ftstack::diag
