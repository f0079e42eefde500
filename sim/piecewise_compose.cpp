#include "sim/piecewise_compose.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "sim/record.hpp"

namespace ftstack::sim {
namespace {

/// Seconds after which the dynamics of `effects` have forgotten their start (12 time constants).
double WarmUpS(const std::vector<Effect>& effects) {
  double s = 0.0;
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kCreep) s = std::max(s, 12.0 * e.num.at("tau_s"));
    if (e.kind == EffectKind::kResonance) {
      const double decay_per_s =
          2.0 * std::numbers::pi * e.num.at("freq_hz") * e.num.at("damping_ratio");
      s = std::max(s, decay_per_s > 0 ? 12.0 / decay_per_s : PiecewiseComposition::kMaxWarmUpS);
    }
    if (e.kind == EffectKind::kHysteresis) s = PiecewiseComposition::kMaxWarmUpS;
  }
  return std::min(s, PiecewiseComposition::kMaxWarmUpS);
}

}  // namespace

PiecewiseComposition::PiecewiseComposition(const SensorModel& model, LoadProfile profile,
                                           double rate_hz, std::vector<Effect> effects,
                                           std::size_t piece_rows)
    : model_(model), profile_(std::move(profile)), rate_hz_(rate_hz), effects_(std::move(effects)) {
  rows_ = static_cast<std::size_t>(std::floor(profile_.duration_s() * rate_hz + 1e-9)) + 1;
  piece_rows_ = std::max<std::size_t>(piece_rows, 1);
  warm_rows_ = static_cast<std::size_t>(std::ceil(WarmUpS(effects_) * rate_hz));
  const std::size_t stride = (rows_ + kSpanGridRows - 1) / kSpanGridRows;
  for (std::size_t i = 0; i < rows_; i += stride) {
    span_grid_s_.push_back(static_cast<double>(i) / rate_hz);
  }
  if (span_grid_s_.back() < static_cast<double>(rows_ - 1) / rate_hz) {
    span_grid_s_.push_back(static_cast<double>(rows_ - 1) / rate_hz);
  }
  // Saturation limits from the effect-free prediction over the span's grid.
  ComposeInput grid;
  grid.model = &model_;
  grid.profile = &profile_;
  grid.rated = model_.rated();
  grid.t_s = span_grid_s_;
  for (const double t : grid.t_s) grid.temp_c.push_back(profile_.TemperatureAt(t));
  DefaultSaturationLimits(sim::Compose({}, grid), &effects_);
}

ComposedPiece PiecewiseComposition::Compose(std::size_t index) const {
  const std::size_t first = std::min(index * piece_rows_, rows_ - 1);
  const std::size_t end = std::min(first + piece_rows_, rows_);
  const std::size_t start = first > warm_rows_ ? first - warm_rows_ : 0;
  ComposeInput in;
  in.model = &model_;
  in.profile = &profile_;
  in.rated = model_.rated();
  in.span_t_s = &span_grid_s_;
  in.row0 = start;
  in.span_rows = rows_;
  in.t_s.resize(end - start);
  in.temp_c.resize(end - start);
  for (std::size_t i = start; i < end; ++i) {
    in.t_s[i - start] = static_cast<double>(i) / rate_hz_;
    in.temp_c[i - start] = profile_.TemperatureAt(in.t_s[i - start]);
  }
  const Eigen::MatrixXd all = sim::Compose(effects_, in);
  ComposedPiece piece;
  piece.first_row = first;
  const auto skip = static_cast<Eigen::Index>(first - start);
  piece.mvv = all.rightCols(all.cols() - skip);
  piece.temp_c.assign(in.temp_c.begin() + skip, in.temp_c.end());
  return piece;
}

}  // namespace ftstack::sim
