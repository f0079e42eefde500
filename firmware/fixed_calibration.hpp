// Conversion of a floating-point calibration into the core's fixed-point form, with overflow proof.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"
#include "hal/adc.hpp"

namespace ftstack::fw {

using hal::kMaxChannels;

/// A linear calibration in physical units, as fitted on the host (calibration/) or read from a
/// calibration file: wrench = matrix · (bridge_mvv − offset_mvv) + bias.
struct FloatCalibration {
  std::uint8_t channel_count = 0;  ///< N bridges, 1 … kMaxChannels
  /// Row r: N (r < 3) or N·m (r ≥ 3) per mV/V of bridge c. Entries c ≥ channel_count ignored.
  std::array<std::array<double, kMaxChannels>, kAxes> matrix{};
  std::array<double, kMaxChannels> offset_mvv{};  ///< bridge zero, mV/V
  std::array<double, kAxes> bias{};               ///< added wrench, N and N·m
};

/// The same calibration in the core's integer form. For row r:
///   y_r[LSB] = round((Σ_c coef[r][c] · x_c + bias[r]) / 2^shift[r]),  x_c = counts_c − zero_c
/// with 64-bit accumulation. The loader proves that no partial sum can leave ±2^62 and that
/// the result fits in int32 for every input between the ADC rails.
struct FixedCalibration {
  std::uint8_t channel_count = 0;
  std::array<std::array<std::int64_t, kMaxChannels>, kAxes> coef{};  ///< LSB/count · 2^shift
  std::array<std::int64_t, kAxes> bias{};   ///< (bias − matrix·offset) in LSB · 2^shift
  std::array<std::uint8_t, kAxes> shift{};  ///< per-row binary point, 0 … 62
  std::int32_t min_counts = 0;              ///< ADC rails the proof was made for
  std::int32_t max_counts = 0;
  bool valid = false;
};

/// Why a calibration was refused.
enum class LoadStatus : std::uint8_t {
  kOk = 0,
  kBadChannelCount,  ///< channel_count outside 1 … kMaxChannels or not the ADC's
  kNotFinite,        ///< a NaN or infinity in matrix, offset or bias
  kBadAdcScaling,    ///< ADC info without a usable full scale or rails
  kOutputOverflow,   ///< some input between the rails would drive an axis past int32
};

[[nodiscard]] const char* ToString(LoadStatus s);

/// What the loader proved about the fixed-point form.
struct LoadReport {
  LoadStatus status = LoadStatus::kOk;
  std::uint8_t failing_axis = 0;  ///< axis that caused kOutputOverflow
  /// Largest |output| any input between the rails can produce, LSB (before int32 clamping).
  std::array<double, kAxes> worst_case_output_lsb{};
  /// Bound on |fixed − exact| over the whole input range, LSB (includes the final rounding).
  std::array<double, kAxes> worst_case_error_lsb{};
  /// The same bound in N (forces) and N·m (moments).
  std::array<double, kAxes> worst_case_error_si{};
};

/// Converts `cal` for an ADC described by `adc` (rails and ratiometric full scale).
/// Runs at start-up (uses floating point); the per-sample path never does.
/// On refusal `*out` is left untouched, so a previously loaded calibration stays usable.
[[nodiscard]] LoadStatus LoadCalibration(const FloatCalibration& cal, const hal::AdcInfo& adc,
                                         FixedCalibration* out, LoadReport* report);

/// Counts per mV/V for an ADC (max_counts / full-scale mV/V); 0 when the scaling is unusable.
[[nodiscard]] double CountsPerMvv(const hal::AdcInfo& adc);

}  // namespace ftstack::fw
