// The per-sample fixed-point core: counts − tare → calibration matrix → wrench, filter, status.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/fixed_calibration.hpp"
#include "firmware/narrow_sum.hpp"
#include "firmware/status_bits.hpp"
#include "firmware/wrench.hpp"
#include "hal/adc.hpp"

namespace ftstack::fw {

/// Largest moving-average length (Modbus holding register 1 accepts 1 … kMaxFilterLength).
inline constexpr std::uint16_t kMaxFilterLength = 256;
/// Largest number of samples one tare may average.
inline constexpr std::uint16_t kMaxTareSamples = 4096;

/// Result of one processed sample.
struct CoreOutput {
  WrenchLsb wrench{};      ///< filtered wrench, LSB (mN, 10 µN·m); held on saturation
  WrenchLsb unfiltered{};  ///< this sample's wrench before the moving average, LSB
  /// The load the sensor body carries: this sample's wrench before the moving average and without
  /// the tare (the calibration's own zero), LSB. Computed also while a bridge is saturated (from
  /// the counts clamped at the rails: then a lower bound of the true load). Overload and peaks use
  /// it. Valid when `structural_valid`.
  WrenchLsb structural{};
  bool structural_valid = false;
  /// A bridge is saturated and got there by ramping through its range: the load drove it there.
  bool saturated_by_load = false;
  std::uint16_t status = 0;  ///< StatusBit set that the core decides (0, 2, 3, 4, 5, 7, 10)
  bool arithmetic_saturated = false;  ///< an intermediate value was clamped this sample
  bool updated = false;               ///< the wrench was recomputed (false while holding)
};

/// Fault-detection thresholds (samples).
struct CoreLimits {
  std::uint16_t stuck_samples = 64;  ///< identical counts on all channels this long → ADC fault
  std::uint16_t rail_samples = 8;    ///< a channel pinned at a rail this long → bridge fault
};

/// The integer-only sample path. Owns no heap; all state is fixed-size. Not thread-safe: one
/// sampling thread calls Process; commands (tare, filter length) come through the same thread.
class WrenchCore {
 public:
  WrenchCore() = default;

  /// Installs a calibration proven by LoadCalibration. An invalid one clears the wrench and sets
  /// kStatusCalInvalid until a valid one is installed.
  void SetCalibration(const FixedCalibration& cal);
  [[nodiscard]] const FixedCalibration& calibration() const { return cal_; }

  /// Fault thresholds; a zero disables that check.
  void SetLimits(const CoreLimits& limits) { limits_ = limits; }

  /// Starts a tare over the next `samples` valid samples (1 … kMaxTareSamples); the previous tare
  /// stays in effect until the new one completes. Returns false for an out-of-range count.
  [[nodiscard]] bool RequestTare(std::uint16_t samples);
  /// Removes the tare: the calibration's own zero and bias apply again.
  void ClearTare();
  [[nodiscard]] bool tare_active() const { return tare_active_; }
  [[nodiscard]] bool tare_pending() const { return tare_remaining_ > 0; }
  /// The wrench of the active tare (untared − tared: the mean load it removed), sensor frame, LSB;
  /// zero without one.
  [[nodiscard]] const WrenchLsb& tare_offset() const { return tare_offset_; }

  /// Moving-average length, 1 … kMaxFilterLength; false (and unchanged) otherwise. Restarts the
  /// filter.
  [[nodiscard]] bool SetFilterLength(std::uint16_t length);
  [[nodiscard]] std::uint16_t filter_length() const { return filter_length_; }

  /// Processes one ADC sample (integer arithmetic only).
  void Process(const hal::AdcSample& in, bool simulated, CoreOutput& out);

  /// The unfiltered matrix step alone (exposed for tests and `ftcal apply`): y = M·(x − zero) + b.
  /// Counts outside the calibration's rails are clamped and reported through *saturated.
  /// A temperature-compensated calibration is evaluated at its reference temperature.
  void Apply(const std::array<std::int32_t, kMaxChannels>& counts, WrenchLsb& y,
             bool* saturated) const;
  /// The same with the body temperature (m°C): second-order and temperature features included.
  /// A temperature outside the compensated range is clamped and reported through *temp_range
  /// (as is a missing one, which is taken as the reference temperature).
  void Apply(const std::array<std::int32_t, kMaxChannels>& counts, std::int32_t temperature_mdegc,
             bool has_temperature, WrenchLsb& y, bool* saturated, bool* temp_range) const;

 private:
  /// What the fault detection found on one sample's raw counts.
  struct Faults {
    bool any_saturated = false;  ///< the backend flagged a channel within 1 % of a rail
    bool any_error = false;      ///< a read error or time-out
    bool bridge_fault = false;   ///< a channel held at a rail it jumped to
    bool jumped = false;         ///< a channel reached saturation by a jump (a broken gauge)
  };
  /// Fault detection on the raw counts; sets the fault status bits in out.
  [[nodiscard]] Faults DetectFaults(const hal::AdcSample& in, CoreOutput& out);
  /// The first sample's rails: true when two or more channels sit at the same rail (a load).
  [[nodiscard]] bool FirstSampleRailsAreLoad(const hal::AdcSample& in) const;
  /// Tare accumulation of one usable sample; activates the tare when complete.
  void AccumulateTare(const hal::AdcSample& in, std::int32_t dt_mdegc);
  /// Moving average of y over the last filter_length_ samples into out.wrench.
  void Filter(const WrenchLsb& y, CoreOutput& out);
  void ResetFilter();
  /// Rearranges the installed calibration for the per-sample path (see Plan).
  void BuildPlan();
  /// Clamps a temperature into the compensated range and returns ΔT, m°C.
  std::int32_t DeltaT(std::int32_t temperature_mdegc, bool has_temperature,
                      bool* out_of_range) const;

  /// Row-interleaved coefficients: [channel or product][axis].
  using Columns = std::array<std::array<std::int64_t, kAxes>, kMaxChannels>;
  /// The counts coefficients and the constant of every row at ΔT (m°C), untared.
  void Effective(std::int32_t dt_mdegc, Columns& eff, std::array<std::int64_t, kAxes>& k) const;
  /// Recomputes the cache (eff_, konst_) for ΔT; a constant of the temperature and the tare.
  void UpdateEffective(std::int32_t dt_mdegc) const;
  /// Σ eff·v + Σ q·p (+ acc's start value) for clamped counts v: the per-sample sum.
  void Accumulate(const std::array<std::int32_t, kMaxChannels>& v, const Columns& eff,
                  std::array<std::int64_t, kAxes>& acc) const;
  /// The same model in the narrow form (FixedCalibration::narrow) with the cached narrow_tab_, for
  /// raw counts that it clamps to the rails (clamped set when it had to), with second-order
  /// features: q = the sum shifted right by each row's binary point (before the saturation).
  void ApplyNarrow(const std::array<std::int32_t, kMaxChannels>& counts,
                   std::array<std::int64_t, kAxes>& q, bool& clamped) const;
  /// The narrow form without second-order features for N channels, whole (clamp, sum, shift,
  /// int32 saturation, *saturated set when clamped or saturated): BuildPlan points
  /// narrow_linear_ at the instance for the calibration's N.
  template <std::size_t N>
  void ApplyNarrowLinear(const std::array<std::int32_t, kMaxChannels>& counts, WrenchLsb& y,
                         bool* saturated) const;
  using LinearFn = void (WrenchCore::*)(const std::array<std::int32_t, kMaxChannels>&, WrenchLsb&,
                                        bool*) const;

  /// The calibration as the per-sample path reads it. Temperature terms never reach the
  /// per-sample sum: the ΔT feature, and each ΔT product C_c·round(x̃_c·ΔT/2^h) evaluated as
  /// round(C_c·ΔT/2^h)·x̃_c, fold into counts coefficients and a constant that are recomputed
  /// only when ΔT changes (Effective). What remains per sample is one product per counts
  /// coefficient and per second-order coefficient, feature-major so each feature multiplies into
  /// six independent accumulators. LoadCalibration proves the bounds of this evaluation order
  /// (EvaluationFits in fixed_calibration.cpp) and its rounding error.
  struct Plan {
    std::uint8_t channels = 0;  ///< bridges (0 for an invalid calibration)
    std::uint8_t products = 0;  ///< second-order features
    bool temperature = false;   ///< ΔT terms present (the cache depends on ΔT)
    std::array<std::int32_t, kMaxChannels> zero{};  ///< x̃ origin, counts
    Columns coef{};                                 ///< counts coefficients at ΔT = 0
    Columns drift{};                                ///< C_c per axis (0 without a ΔT product)
    std::array<std::uint8_t, kMaxChannels> drift_shift{};
    std::array<std::int64_t, kMaxChannels> drift_half{};
    std::array<std::int64_t, kAxes> temp_coef{};  ///< coefficient of ΔT
    std::array<std::int64_t, kAxes> bias{};
    std::array<std::uint8_t, kMaxProducts> a{};  ///< bridges of a product
    std::array<std::uint8_t, kMaxProducts> b{};
    std::array<std::uint8_t, kMaxProducts> shift{};                    ///< its rounded shift
    std::array<std::int64_t, kMaxProducts> half{};                     ///< its rounding half
    std::array<std::array<std::int64_t, kAxes>, kMaxProducts> quad{};  ///< [product][axis]
    std::array<std::int64_t, kAxes> round_half{};                      ///< of each row's shift
    /// Narrow form: with c' = round(c / 2^k_r) (|c'| < 2^31) and x' = x + 2^31, c'·x' summed in
    /// uint64 (SSE2 pmuludq lanes; a scalar loop elsewhere), then Σ c·x = Σ c'_u·x'_u − 2^31·Σ c'_u
    /// − 2^31·Σ x'_u + F·2^62 modulo 2^64, exact because the loader bounds the true sum.
    bool narrow = false;
    std::array<std::uint8_t, kAxes> narrow_shift{};          ///< k of the counts
    std::array<std::uint8_t, kAxes> narrow_product_shift{};  ///< k of the products
    std::array<std::int64_t, kAxes> narrow_half{};           ///< rounding half of the counts' k
    std::array<std::array<std::uint64_t, kAxes>, kMaxProducts> quad_u{};  ///< q' + 2^31
    std::array<std::uint64_t, kAxes> quad_k{};  ///< 2^31·Σ_j q'_u − P·2^62 mod 2^64
    /// s_r − k_r: the counts sum T_r = floor(acc_r / 2^k_r) needs only this shift without
    /// products (floor(floor(a/2^k)/2^(s−k)) = floor(a/2^s); the plan is narrow only if k ≤ s).
    std::array<std::uint8_t, kAxes> final_shift{};
    narrow::Final final{};  ///< the same shifts for narrow::ShiftToI32
    std::array<std::uint64_t, kMaxChannels> lo_minus_zero{};  ///< lower rail − zero_c, mod 2^64
  };

  // The 16-byte aligned members first (SIMD loads), then the rest.
  mutable narrow::Table narrow_tab_{};  ///< the narrow coefficients at eff_dt_
  Plan plan_{};
  LinearFn narrow_linear_ = nullptr;
  FixedCalibration cal_{};
  // A cache of values derived from the calibration, the tare and the last ΔT (mutable: Apply is
  // const; WrenchCore is single-threaded by contract).
  mutable Columns eff_{};  ///< counts coefficients at eff_dt_ (64-bit form only)
  mutable std::array<std::int64_t, kAxes> konst_{};  ///< constant at eff_dt_ minus tare_acc_
  mutable std::int32_t eff_dt_ = 0;
  mutable std::array<std::int64_t, kAxes> narrow_low_{};  ///< konst_ mod 2^k_r
  /// The untared sum at the tare (zero without one): subtracting it makes every feature relative
  /// to its value at the tare and drops the bias.
  std::array<std::int64_t, kAxes> tare_acc_{};
  CoreLimits limits_{};
  std::array<std::int32_t, kMaxChannels> tare_counts_{};
  bool tare_active_ = false;
  std::uint16_t tare_remaining_ = 0;
  std::uint16_t tare_total_ = 0;
  std::array<std::int64_t, kMaxChannels> tare_sum_{};
  std::int64_t tare_temp_sum_ = 0;  ///< Σ clamped ΔT over the tare, m°C
  WrenchLsb tare_offset_{};         ///< untared − tared wrench while a tare is active, LSB

  std::uint16_t filter_length_ = 1;
  std::uint16_t filter_fill_ = 0;
  std::uint16_t filter_pos_ = 0;
  std::array<std::array<std::int32_t, kAxes>, kMaxFilterLength> filter_ring_{};
  std::array<std::int64_t, kAxes> filter_sum_{};

  WrenchLsb last_valid_{};
  std::array<std::int32_t, kMaxChannels> last_counts_{};
  std::uint16_t same_count_run_ = 0;
  std::array<std::uint16_t, kMaxChannels> rail_run_{};
  /// The channel reached its rail in one step from inside half its range: an open or shorted
  /// gauge, not a load (a load ramps through the range; an open gauge jumps).
  std::array<bool, kMaxChannels> rail_jump_{};
  std::array<bool, kMaxChannels> was_saturated_{};  ///< saturated in the previous sample
  bool seen_sample_ = false;  ///< a sample was processed (last_counts_ holds a real one)
};

}  // namespace ftstack::fw
