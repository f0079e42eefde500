#include "firmware/fixed_calibration.hpp"

#include <cmath>
#include <limits>

namespace ftstack::fw {

const char* ToString(LoadStatus s) {
  switch (s) {
    case LoadStatus::kOk:
      return "ok";
    case LoadStatus::kBadChannelCount:
      return "channel count outside 1..8 or different from the ADC's";
    case LoadStatus::kNotFinite:
      return "calibration contains NaN or infinity";
    case LoadStatus::kBadAdcScaling:
      return "ADC scaling unusable (full scale or rails)";
    case LoadStatus::kOutputOverflow:
      return "worst-case output overflows int32 (matrix too large for the ADC range)";
  }
  return "unknown";
}

double CountsPerMvv(const hal::AdcInfo& adc) {
  if (adc.full_scale_nvv <= 0 || adc.max_counts <= 0 || adc.min_counts >= 0) return 0.0;
  return static_cast<double>(adc.max_counts) / (static_cast<double>(adc.full_scale_nvv) * 1e-6);
}

LoadStatus LoadCalibration(const FloatCalibration& cal, const hal::AdcInfo& adc,
                           FixedCalibration* out, LoadReport* report) {
  LoadReport rep{};
  auto finish = [&](LoadStatus s) {
    rep.status = s;
    if (report != nullptr) *report = rep;
    return s;
  };
  const std::size_t n = cal.channel_count;
  if (n < 1 || n > kMaxChannels || (adc.channel_count != 0 && adc.channel_count != n)) {
    return finish(LoadStatus::kBadChannelCount);
  }
  const double counts_per_mvv = CountsPerMvv(adc);
  if (!(counts_per_mvv > 0) || !std::isfinite(counts_per_mvv)) {
    return finish(LoadStatus::kBadAdcScaling);
  }
  for (std::size_t r = 0; r < kAxes; ++r) {
    if (!std::isfinite(cal.bias[r])) return finish(LoadStatus::kNotFinite);
    for (std::size_t c = 0; c < n; ++c) {
      if (!std::isfinite(cal.matrix[r][c]) || !std::isfinite(cal.offset_mvv[c])) {
        return finish(LoadStatus::kNotFinite);
      }
    }
  }
  // Largest |x| = |counts − zero| with counts and zero (a tare or the offset) between the rails.
  const double x_span = static_cast<double>(adc.max_counts) - static_cast<double>(adc.min_counts);
  FixedCalibration fixed{};
  fixed.channel_count = static_cast<std::uint8_t>(n);
  fixed.min_counts = adc.min_counts;
  fixed.max_counts = adc.max_counts;
  constexpr double kInt32Max = static_cast<double>(std::numeric_limits<std::int32_t>::max());
  for (std::size_t r = 0; r < kAxes; ++r) {
    const double lsb = AxisLsb(r);
    std::array<double, kMaxChannels> m{};  // LSB per count
    double bias_lsb = cal.bias[r] / lsb;
    double worst = 0.0;
    for (std::size_t c = 0; c < n; ++c) {
      m[c] = cal.matrix[r][c] / lsb / counts_per_mvv;
      bias_lsb -= m[c] * (cal.offset_mvv[c] * counts_per_mvv);
      worst += std::fabs(m[c]) * x_span;
    }
    worst += std::fabs(bias_lsb);
    rep.worst_case_output_lsb[r] = worst;
    if (!std::isfinite(worst) || worst + 1.0 > kInt32Max) {
      rep.failing_axis = static_cast<std::uint8_t>(r);
      return finish(LoadStatus::kOutputOverflow);
    }
    // Largest binary point with (worst + rounding + coefficient rounding) · 2^s ≤ 2^61:
    // every partial sum then stays inside ±2^62 and adding the rounding half cannot overflow.
    int s = 61 - static_cast<int>(std::ceil(std::log2(worst + static_cast<double>(n) + 2.0)));
    if (s > 62) s = 62;
    if (s < 0) s = 0;
    const double scale = std::ldexp(1.0, s);
    for (std::size_t c = 0; c < n; ++c) {
      fixed.coef[r][c] = std::llround(m[c] * scale);
    }
    fixed.bias[r] = std::llround(bias_lsb * scale);
    fixed.shift[r] = static_cast<std::uint8_t>(s);
    // Each coefficient and the bias are off by at most half a unit of 2^-s; the final rounding
    // adds half an LSB.
    const double err = 0.5 / scale * (x_span * static_cast<double>(n) + 1.0) + 0.5;
    rep.worst_case_error_lsb[r] = err;
    rep.worst_case_error_si[r] = err * lsb;
  }
  fixed.valid = true;
  *out = fixed;
  return finish(LoadStatus::kOk);
}

}  // namespace ftstack::fw
