#include "calibration/fit/model.hpp"

#include <algorithm>

namespace ftstack::cal {

std::array<double, 6> EvaluateCalibration(const fw::FloatCalibration& cal, const double* bridge_mvv,
                                          double temperature_c) {
  const std::size_t n = cal.channel_count;
  std::array<double, fw::kMaxChannels> x{};
  for (std::size_t c = 0; c < n; ++c) x[c] = bridge_mvv[c] - cal.offset_mvv[c];
  // Per-channel compensation: x' = x − α·ΔT − γ·x·ΔT.
  std::array<double, fw::kMaxChannels> xc = x;
  if (cal.temperature_compensated) {
    const double t = std::clamp(temperature_c, cal.temp_min_c, cal.temp_max_c);
    const double dt = t - cal.temp_ref_c;
    for (std::size_t c = 0; c < n; ++c) {
      xc[c] = x[c] - cal.bias_slope_mvv_per_c[c] * dt - cal.gain_slope_per_c[c] * x[c] * dt;
    }
  }
  std::array<double, 6> y{};
  for (std::size_t r = 0; r < 6; ++r) {
    double acc = cal.bias[r];
    for (std::size_t c = 0; c < n; ++c) acc += cal.matrix[r][c] * xc[c];
    for (std::size_t k = 0; k < cal.product_count; ++k) {
      acc += cal.product_matrix[r][k] * x[cal.products[k].a] * x[cal.products[k].b];
    }
    y[r] = acc;
  }
  return y;
}

}  // namespace ftstack::cal
