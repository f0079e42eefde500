// A long simulated recording's bridge outputs composed piece by piece, in bounded memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "sim/effects.hpp"
#include "sim/load_profile.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// One piece: rows [first_row, first_row + cols) of the recording.
struct ComposedPiece {
  std::size_t first_row = 0;
  Eigen::MatrixXd mvv;         ///< N × rows, mV/V, noise-free, effects applied
  std::vector<double> temp_c;  ///< body temperature per row
};

/// What ComposeWithEffects gives for the whole of `profile` at `rate_hz`, a piece at a time. Each
/// piece is composed from a warm-up before it (the dynamics' memory: 12 time constants of creep,
/// 12 of the resonance's decay, at most kMaxWarmUpS), so a piece differs from the whole by what
/// is left after that (e^-12 of a creep still running); hysteresis starts relaxed at the warm-up.
/// Slow wanders and saturation limits are laid out over a grid of at most kSpanGridRows times of
/// the whole span (exact when the recording has no more rows). Thread-compatible: Compose is const.
class PiecewiseComposition {
 public:
  static constexpr double kMaxWarmUpS = 60.0;
  static constexpr std::size_t kSpanGridRows = 100000;

  /// `effects` resolved for `profile` (ResolveEffects); the model must outlive this.
  PiecewiseComposition(const SensorModel& model, LoadProfile profile, double rate_hz,
                       std::vector<Effect> effects, std::size_t piece_rows);

  [[nodiscard]] std::size_t rows() const { return rows_; }
  [[nodiscard]] std::size_t piece_rows() const { return piece_rows_; }
  [[nodiscard]] std::size_t warm_up_rows() const { return warm_rows_; }
  [[nodiscard]] std::size_t pieces() const { return (rows_ + piece_rows_ - 1) / piece_rows_; }
  [[nodiscard]] const std::vector<Effect>& effects() const { return effects_; }
  /// Piece `index` (0 … pieces() − 1).
  [[nodiscard]] ComposedPiece Compose(std::size_t index) const;

 private:
  const SensorModel& model_;
  LoadProfile profile_;
  double rate_hz_;
  std::vector<Effect> effects_;
  std::size_t rows_ = 0;
  std::size_t piece_rows_ = 0;
  std::size_t warm_rows_ = 0;
  std::vector<double> span_grid_s_;
};

}  // namespace ftstack::sim
