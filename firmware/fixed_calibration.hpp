// Conversion of a floating-point calibration into the core's fixed-point form, with overflow proof.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"
#include "hal/adc.hpp"

namespace ftstack::fw {

using hal::kMaxChannels;

/// Largest number of second-order terms: every product of two of kMaxChannels bridges.
inline constexpr std::size_t kMaxProducts = kMaxChannels * (kMaxChannels + 1) / 2;
/// Largest number of integer features one row sums: bridges, ΔT, products, bridge × ΔT.
inline constexpr std::size_t kMaxFeatures = kMaxChannels + 1 + kMaxProducts + kMaxChannels;

/// A second-order term: the product of bridges a and b (a ≤ b), each minus its offset.
struct ProductTerm {
  std::uint8_t a = 0;
  std::uint8_t b = 0;
};

/// A calibration in physical units, as fitted on the host (calibration/) or read from a file.
/// With x_c = bridge_mvv_c − offset_mvv_c and ΔT = T − temp_ref_c (T clamped to the compensated
/// range [temp_min_c, temp_max_c]):
///   wrench = matrix · (x − α·ΔT − (γ∘x)·ΔT) + Σ_k product_matrix[·][k] · x_a(k) · x_b(k) + bias
/// where α = bias_slope_mvv_per_c and γ = gain_slope_per_c (per-channel temperature compensation
/// as commercial sensors do it against a thermistor channel). Without temperature compensation or
/// product terms this is the plain affine calibration wrench = matrix · (bridge − offset) + bias.
struct FloatCalibration {
  std::uint8_t channel_count = 0;  ///< N bridges, 1 … kMaxChannels
  /// Row r: N (r < 3) or N·m (r ≥ 3) per mV/V of bridge c. Entries c ≥ channel_count ignored.
  std::array<std::array<double, kMaxChannels>, kAxes> matrix{};
  std::array<double, kMaxChannels> offset_mvv{};  ///< bridge zero, mV/V
  std::array<double, kAxes> bias{};               ///< added wrench, N and N·m

  std::uint8_t product_count = 0;  ///< second-order terms used, 0 … kMaxProducts
  std::array<ProductTerm, kMaxProducts> products{};
  /// Row r, term k: N or N·m per (mV/V)².
  std::array<std::array<double, kMaxProducts>, kAxes> product_matrix{};

  bool temperature_compensated = false;
  double temp_ref_c = 20.0;   ///< reference temperature, °C
  double temp_min_c = -20.0;  ///< compensated range, °C (outside: clamped, status bit 6)
  double temp_max_c = 80.0;
  std::array<double, kMaxChannels> bias_slope_mvv_per_c{};  ///< α: zero drift, mV/V per °C
  std::array<double, kMaxChannels> gain_slope_per_c{};      ///< γ: sensitivity drift, 1 per °C
  /// Bit r set: axis r was not determined by the calibration (its rig never excited it); the
  /// core outputs 0 for it and the device never serves it as a value (status bit 10).
  std::uint8_t invalid_axes = 0;
};

/// Kinds of the integer features after the N bridge channels.
enum class FeatureKind : std::uint8_t {
  kTemperature = 0,  ///< ΔT in m°C
  kProduct,          ///< round(x̃_a · x̃_b / 2^shift), x̃ = counts − zero
  kTempProduct,      ///< round(x̃_a · ΔT / 2^shift)
};

/// One feature after the bridge channels.
struct FixedFeature {
  FeatureKind kind = FeatureKind::kTemperature;
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  std::uint8_t shift = 0;  ///< right shift (rounded) applied to the product, 0 … 62
};

/// The same calibration in the core's integer form. Features f: f_c = counts_c for the N
/// channels, then `extra_count` features (ΔT, products) described by `extra`. For row r:
///   y_r[LSB] = round((Σ_k coef[r][k] · f_k + bias[r]) / 2^shift[r])
/// with 64-bit accumulation (with an active tare every f is taken relative to its value at the
/// tare and the bias is dropped). The core evaluates it in another order (temperature terms folded
/// into per-ΔT counts coefficients, C_c·round(x̃_c·ΔT/2^h) taken as round(C_c·ΔT/2^h)·x̃_c,
/// optionally the narrow form below); the loader proves for that order that no partial sum can
/// leave ±2^62, that the result fits in int32 for every input between the ADC rails, and bounds
/// its error (LoadReport).
struct FixedCalibration {
  std::uint8_t channel_count = 0;
  std::array<std::array<std::int64_t, kMaxFeatures>, kAxes> coef{};  ///< LSB/feature · 2^shift
  std::array<std::int64_t, kAxes> bias{};   ///< (bias − matrix·offset) in LSB · 2^shift
  std::array<std::uint8_t, kAxes> shift{};  ///< per-row binary point, 0 … 62
  std::int32_t min_counts = 0;              ///< ADC rails the proof was made for
  std::int32_t max_counts = 0;
  std::uint8_t extra_count = 0;  ///< features after the channels
  std::array<FixedFeature, kMaxFeatures - kMaxChannels> extra{};
  std::array<std::int32_t, kMaxChannels> zero{};  ///< x̃ origin of product features, counts
  bool temperature = false;                       ///< the calibration uses the temperature
  std::int32_t temp_ref_mdegc = 0;                ///< ΔT origin, m°C
  std::int32_t temp_min_mdegc = 0;                ///< compensated range, m°C
  std::int32_t temp_max_mdegc = 0;
  std::uint8_t invalid_axes = 0;  ///< bit r: axis r not calibrated (see FloatCalibration)
  /// The core may sum 32-bit coefficients round(coef / 2^narrow_shift[r]) (counts, at every ΔT)
  /// and round(coef / 2^narrow_product_shift[r]) (products) times 32-bit features into 64-bit
  /// sums scaled back by those powers of two (SIMD-friendly): proven by the loader with the same
  /// bounds, its extra rounding included in the reported error.
  bool narrow = false;
  std::array<std::uint8_t, kAxes> narrow_shift{};
  std::array<std::uint8_t, kAxes> narrow_product_shift{};
  bool valid = false;
};

/// Why a calibration was refused.
enum class LoadStatus : std::uint8_t {
  kOk = 0,
  kBadChannelCount,  ///< channel_count outside 1 … kMaxChannels or not the ADC's
  kNotFinite,        ///< a NaN or infinity in matrix, offset or bias
  kBadAdcScaling,    ///< ADC info without a usable full scale or rails
  kOutputOverflow,   ///< some input between the rails would drive an axis past int32
  kBadTerms,         ///< product term out of range, or temperature range/reference unusable
  /// A second-order feature's raw product (x̃_a·x̃_b or x̃·ΔT, plus its rounding half) could pass
  /// int64 for inputs between the rails (ADC rails too wide for the product terms).
  kFeatureOverflow,
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
