// The health watch in the sampling path: zero, temperature, interference, mount and creep findings.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/health_signal.hpp"
#include "firmware/health_types.hpp"
#include "firmware/rainflow.hpp"
#include "firmware/wrench.hpp"

namespace ftstack::fw {

/// What the watch sees of one sample.
struct HealthInput {
  WrenchLsb tared{};   ///< this sample's wrench before the moving average (tared when a tare is on)
  bool valid = false;  ///< a measurement: calibrated, no bridge at a rail, no clipped arithmetic
  std::int32_t temperature_mdegc = 0;
  bool has_temperature = false;
  std::uint16_t status = 0;  ///< the device's status bits of this sample (for the NE 107 state)
  bool tare_pending = false;
  WrenchLsb untared{};  ///< the load the body carries (no tare), also at a rail (a lower bound)
  bool untared_valid = false;
};

/// Integer-only; no heap; the cost of one Step is bounded: a few hundred operations, plus at most
/// one slice of kRingSlice samples of a ringing analysis (after a transient capture ends, its six
/// axes are analysed a slice per sample: 4 samples per axis).
/// Single-threaded: the sampling thread calls everything.
/// Members are grouped by watch, not by size: some padding in a 20 KB object.
class HealthWatch {  // NOLINT(clang-analyzer-optin.performance.Padding)
 public:
  static constexpr std::size_t kRingCapture = 512;  ///< samples of a transient capture
  static constexpr std::size_t kRingSlice = 128;    ///< capture samples analysed per Step
  static constexpr std::size_t kLevelRing = 128;    ///< sub-block means of the 0.1 s level
  static constexpr std::uint32_t kCreepHolds = 3;   ///< still holds that must agree on a creep
  static constexpr std::size_t kToneBlocks = 8;     ///< judged blocks a tone or noise is read over

  /// Rate and rated range per axis (LSB, each > 0). False (the watch stays off) otherwise, or at
  /// a rate below 100 Hz.
  [[nodiscard]] bool Configure(std::uint32_t rate_hz, const WrenchLsb& rated_lsb);
  [[nodiscard]] bool configured() const { return configured_; }
  void SetThresholds(const HealthThresholds& t);
  [[nodiscard]] const HealthThresholds& thresholds() const { return th_; }
  /// Learns the noise floor (over the next 5 s of blocks without load changes) and the ringing
  /// frequency (the median of the next 3 measured, unless ring_ref_dhz gives it) anew.
  void Commission();
  /// Clears every finding and the zero history: the reference becomes now.
  void Clear();
  /// A tare completed or was removed: the zero reference becomes now, at this temperature. A
  /// completed tare also enters the history with the load it removed and who asked for it.
  void OnTare(std::int32_t temperature_mdegc, bool has_temperature, bool cleared,
              const WrenchLsb& load_lsb = {}, TareSource source = TareSource::kNone);
  void Step(const HealthInput& in);
  [[nodiscard]] const HealthReport& report() const { return report_; }

 private:
  enum class CreepPhase : std::uint8_t { kIdle, kMoving, kSettling, kHold };
  __extension__ using Int128 = __int128;

  void ResetFilters() {
    filters_ready_ = false;
    ResetLevel();
  }
  void ResetReference(std::int32_t temperature_mdegc, bool has_temperature);
  [[nodiscard]] bool UpdateLevel(const HealthInput& in);
  void ResetLevel();
  void UpdateZero(const HealthInput& in, bool stable);
  void AddZeroPoint(const HealthInput& in);
  void JudgeZero(const HealthInput& in);
  void UpdateBlock(const HealthInput& in, const WrenchLsb& d);
  /// One block's tones and noise per axis, Q8 LSB.
  struct BlockResult {
    std::array<std::int64_t, kAxes> a50{}, a60{}, sigma{};
  };
  void FinishBlock();
  void TakeBlock(const BlockResult& b);
  void UpdateRinging(const HealthInput& in);
  void StartAxis(std::size_t axis);
  void FinishAxis(std::size_t axis);
  void FinishRinging();
  void UpdateCreep(const HealthInput& in, bool moving);
  void TrackHoldLevel();
  void FinishCreep();
  void SetFinding(HealthCause cause, bool on, const WrenchLsb& error);
  /// The watch judged `cause` at this sample (its coverage).
  void Judged(HealthCause cause) { judged_at_[static_cast<std::size_t>(cause) - 1] = samples_; }
  void Publish(const HealthInput& in);

  bool configured_ = false;
  std::uint32_t rate_ = 0;
  WrenchLsb rated_{};
  HealthThresholds th_{};
  // Thresholds in LSB (or samples), derived from th_ and the rated range.
  std::array<std::int64_t, kAxes> window_{}, limit_{}, band_{}, move_{}, step_{};
  std::uint32_t stable_samples_ = 0;
  std::uint8_t fast_shift_ = 0;  ///< fast low-pass: time constant 2^k samples ≈ 0.1 s
  std::uint8_t slow_shift_ = 0;  ///< slow low-pass ≈ 1 s

  std::uint64_t samples_ = 0;
  bool filters_ready_ = false;
  std::array<std::int64_t, kAxes> fast_q8_{}, slow_q8_{};
  WrenchLsb prev_{};

  // The level: the mean over the last 0.1 s (whole periods of 50 and 60 Hz and their harmonics,
  // so a steady tone leaves nothing in it), kept as a ring of sub-block means. A load change is
  // judged on it against the previous whole 0.1 s window, never on a single sample.
  std::uint32_t level_sub_ = 1;     ///< samples per sub-block (block = level_sub_ · level_len_)
  std::uint32_t level_len_ = 1;     ///< sub-blocks in the ring
  std::uint32_t level_pos_ = 0;     ///< samples in the current sub-block
  std::uint32_t level_at_ = 0;      ///< the ring's next slot
  std::uint32_t level_filled_ = 0;  ///< sub-blocks since the last reset (up to 2 · level_len_)
  std::array<std::int64_t, kAxes> level_acc_{};  ///< the current sub-block's sum
  std::array<std::array<std::int32_t, kLevelRing>, kAxes> level_ring_{};
  std::array<std::int64_t, kAxes> level_sum_{};   ///< Σ of the ring: level × level_len_
  std::array<std::int64_t, kAxes> level_prev_{};  ///< that sum at the last wrap of the ring
  bool level_moving_ = true;

  // Zero watch: spells, zero points (one per second of a qualified spell), regression.
  std::uint32_t stable_run_ = 0;
  std::array<std::int64_t, kAxes> zero_sum_{};
  std::uint32_t zero_count_ = 0;
  std::array<std::int64_t, kAxes> zero_last_{};  ///< the last zero point accepted
  bool spell_checked_ = false;   ///< this spell's first zero point was compared with zero_last_
  bool spell_rejected_ = false;  ///< … and was too far from it: a held load, not the zero
  bool overload_seen_ = false;   ///< an overload since the last spell was judged
  std::uint64_t ref_sample_ = 0;
  std::int32_t ref_temp_mdegc_ = 0;
  bool ref_has_temp_ = false;
  std::uint32_t points_ = 0;
  Int128 stt_ = 0, sdd_ = 0;  ///< Σ Δt² (s²), Σ ΔT² ((0.01 K)²)
  std::array<Int128, kAxes> szt_{}, szd_{}, szz_{};
  std::int32_t dtemp_min_ = 0, dtemp_max_ = 0;  ///< ΔT range seen at zero points, 0.01 K

  // Interference: one block of rate/10 samples (50 and 60 Hz on exact bins).
  std::uint32_t block_ = 0;
  std::uint32_t block_pos_ = 0;
  bool block_moved_ = false;
  // A block is judged one block late, and only when the next one did not move either: a load
  // change near a block's end shows in the 0.1 s level only during the next block.
  BlockResult pending_{};
  bool pending_use_ = false;
  std::int64_t inv_sqrt_block_q16_ = 0;  ///< 2^16 / sqrt(block)
  std::int32_t max_diff_ = 0;            ///< first differences are clamped to ± this
  std::array<ToneDetector, kAxes> tone50_{}, tone60_{};
  std::array<std::int64_t, kAxes> sum_d_{}, sum_d2_{};
  // Interference and a noise rise last: each is read as the median of the last kToneBlocks blocks
  // taken, so a transient the moving gate let through (a contact bounce) spoils one block, not
  // the reading. Per block: 50 Hz, 60 Hz amplitude and noise per axis, Q8 LSB, in a ring.
  std::array<std::array<std::array<std::int32_t, kToneBlocks>, kAxes>, 3> block_ring_{};
  std::array<std::int64_t, kAxes> a50_q8_{}, a60_q8_{}, sigma_q8_{};
  std::uint32_t blocks_seen_ = 0;
  std::array<std::int64_t, kAxes> sigma_ref_sum_q8_{}, sigma_ref_q8_{};
  std::uint32_t commission_blocks_ = 0;  ///< blocks still to learn the noise floor from

  // Mount: transient capture (axis-major) and ringing frequencies.
  std::array<std::array<std::int32_t, kRingCapture>, kAxes> capture_{};
  std::uint32_t capture_pos_ = 0;
  bool capturing_ = false;
  std::uint32_t capture_stride_ = 1;
  std::uint32_t stride_count_ = 0;
  std::uint32_t refractory_ = 0;
  std::size_t analysing_ = kAxes;  ///< the capture's axis under analysis (kAxes: none pending)
  RingingScan ring_scan_{};        ///< that axis's analysis, a slice per sample
  std::int32_t ring_h_ = 0;        ///< its hysteresis, LSB: noise bands plus the tones' peaks
  std::int32_t ring_noise_h_ = 0;  ///< the noise's part of it, LSB
  std::int32_t ring_tone_ = 0;     ///< the tones' part of it, LSB
  std::array<RingingResult, kAxes> ring_axis_{};
  std::array<std::int32_t, 3> ring_last_mhz_{};
  std::uint32_t ring_measured_ = 0;
  std::array<std::int32_t, 3> ring_learn_mhz_{};
  std::uint32_t ring_learned_ = 0;
  std::int32_t ring_ref_mhz_ = 0;

  // Creep: a hold after a load change, three equal segments.
  CreepPhase creep_phase_ = CreepPhase::kIdle;
  std::array<std::int64_t, kAxes> pre_level_{};
  std::array<std::array<std::int64_t, kAxes>, 3> seg_sum_{};
  std::uint32_t creep_count_ = 0;
  std::uint32_t seg_len_ = 0;
  // The hold's 0.1 s level (ring sums, every 0.1 s): its extremes and the largest way back from
  // each, so that a load wandering under the moving gate is not read as creep.
  std::array<std::int64_t, kAxes> hold_max_{}, hold_min_{}, retreat_up_{}, retreat_down_{};
  // Independent holds that read as creep, in a row, with the same sign (relative to their step)
  // and time constants within a factor 2 (d2/d1 of the segments: e^(−2 s/τ), Q16).
  std::uint32_t creep_streak_ = 0;
  int creep_sign_ = 0;
  std::int64_t creep_ratio_q16_ = 0;

  // Load history: rainflow cycles of the untared load per axis.
  std::array<RainflowCounter, kAxes> rainflow_{};
  bool cycles_changed_ = true;  ///< a count changed since the report last copied them

  // Findings, and when each cause was last judged (sample count; 0: never).
  std::uint16_t active_ = 0;
  std::array<std::uint64_t, kHealthCauses> judged_at_{};
  std::array<WrenchLsb, kHealthCauses> error_{};
  std::uint32_t tare_sample_ = 0;
  std::uint32_t tares_completed_ = 0;
  HealthReport report_{};
};

}  // namespace ftstack::fw
