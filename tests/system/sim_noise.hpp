// Test helper: per-axis noise of one sample of `ftd --adc sim` and the core's worst-case error.
#pragma once

#include <array>
#include <cmath>

#include "calibration/file/cal_file.hpp"
#include "sim/default_sensor.hpp"
#include "sim/ideal_calibration.hpp"
#include "tests/system/builtin_adc.hpp"

namespace ftstack::test {

/// σ of one sample per axis (the simulated ADC's input noise and quantisation, q²/12, propagated
/// through the ideal calibration) and the fixed-point core's worst-case error, N and N·m.
struct SimNoise {
  std::array<double, 6> sigma{};
  std::array<double, 6> fixed_error{};
};

inline SimNoise DeriveSimNoise() {
  const auto model = sim::MakeDefaultSensor();
  const BuiltinAdc builtin = BuiltinSimAdc();
  const cal::CalFile c = sim::IdealCalibration(*model, builtin.info);
  const double q = builtin.info.full_scale_nvv * 1e-6 / builtin.info.max_counts;
  const double var = builtin.noise_rms_mvv * builtin.noise_rms_mvv + q * q / 12.0;
  SimNoise n;
  for (std::size_t i = 0; i < 6; ++i) {
    double s2 = 0;
    for (std::size_t ch = 0; ch < 6; ++ch) s2 += c.cal.matrix[i][ch] * c.cal.matrix[i][ch] * var;
    n.sigma[i] = std::sqrt(s2);
  }
  fw::LoadReport rep;
  (void)cal::ToFixed(c, builtin.info, &rep);
  n.fixed_error = rep.worst_case_error_si;
  return n;
}

}  // namespace ftstack::test
