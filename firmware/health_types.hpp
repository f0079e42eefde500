// What the health watch reports and how it is configured: causes, NAMUR NE 107 states, thresholds.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/wrench.hpp"

namespace ftstack::fw {

/// NAMUR NE 107 status of the device (input register 100).
enum class Ne107State : std::uint16_t {
  kNormal = 0,
  kFailure = 1,             ///< F: the measurement is not valid (bridge, ADC or calibration fault)
  kCheckFunction = 2,       ///< C: a tare or a commissioning is in progress
  kOffSpecification = 3,    ///< S: overloaded, saturated or outside the compensated temperature
  kMaintenanceRequired = 4  ///< M: valid, but a finding degrades the accuracy
};

/// Cause code of one finding (the physical effect; names as in the effect vocabulary).
enum class HealthCause : std::uint16_t {
  kNone = 0,
  kZeroDrift = 1,         ///< zero moved since the tare / calibration, not with temperature
  kThermalZeroDrift = 2,  ///< zero moved with the temperature since the tare / calibration
  kMains50 = 3,           ///< 50 Hz pick-up
  kMains60 = 4,           ///< 60 Hz pick-up
  kNoiseFloor = 5,        ///< broadband noise above the commissioning's
  kResonanceShift = 6,    ///< first ringing frequency moved from the commissioning's
  kCreep = 7,             ///< the output keeps moving during holds after load changes
  kOverloadShift = 8,     ///< the zero jumped across an overload (plastic yield, a slipped bond)
};
inline constexpr std::size_t kHealthCauses = 8;  ///< causes 1 … 8
/// Finding slots in the register map (the first kHealthSlots active causes, in code order).
inline constexpr std::size_t kHealthSlots = 4;

/// Thresholds, as the holding registers 51 … 59 hold them (units in the names).
struct HealthThresholds {
  std::uint16_t zero_window_bp = 200;     ///< unloaded: |tared load| within this, 0.01 % of rated
  std::uint16_t zero_limit_bp = 50;       ///< zero drift finding above this, 0.01 % of rated
  std::uint16_t stability_bp = 20;        ///< stable: |fast − slow filter| within this, 0.01 %
  std::uint16_t stable_time_ds = 20;      ///< a spell must be stable this long first, 0.1 s
  std::uint16_t mains_limit_bp = 5;       ///< mains pick-up finding above this, 0.01 % of rated
  std::uint16_t noise_factor_d = 30;      ///< noise finding above this × commissioning, 0.1
  std::uint16_t resonance_shift_pm = 50;  ///< resonance finding beyond this shift, 0.1 %
  std::uint16_t creep_limit_bp = 20;      ///< creep finding above this share of the step, 0.01 %
  std::uint16_t ring_ref_dhz = 0;         ///< commissioning ringing frequency, 0.1 Hz (0: learn it)
  bool operator==(const HealthThresholds&) const = default;
};

/// Who asked for a tare (the command reaches the device through one of these).
enum class TareSource : std::uint8_t {
  kNone = 0,    ///< an empty history slot
  kModbus = 1,  ///< holding register 0 = 1 (TCP or RTU)
  kRdt = 2,     ///< ATI RDT command 0x0042 "set software bias" (ftd --rdt)
  kMqtt = 3,    ///< the Sparkplug command Device Control/Tare (ftd --mqtt)
  kWeb = 4,     ///< the web page or its JSON API (ftd --http)
  kOpcua = 5,   ///< an OPC UA method call Tare (ftd --opcua)
};

/// One completed tare, as the history keeps it.
struct TareRecord {
  std::uint32_t number = 0;  ///< 1 for the first tare since start, +1 each; 0: an empty slot
  TareSource source = TareSource::kNone;
  bool has_temperature = false;
  std::uint32_t time_s =
      0;  ///< when it completed: samples the watch has seen ÷ rate (as tare_age_s)
  std::int32_t temperature_mdegc = 0;  ///< at its completion (meaningful when has_temperature)
  WrenchLsb load_lsb{};  ///< the untared wrench it removed (its mean load), sensor frame, LSB
};
/// Tares the history keeps (the newest first).
inline constexpr std::size_t kTareHistory = 4;

/// Rainflow range bins per axis, and their upper edges in % of the axis's rated range: bin k
/// holds full cycles with edge[k − 1] ≤ range < edge[k] (bin 1 from the 2 % turning-point gate,
/// bin 8 from 100 % up).
inline constexpr std::size_t kRainflowBins = 8;
inline constexpr std::array<std::int32_t, kRainflowBins - 1> kRainflowBinEdgesPct = {5,  10, 20, 40,
                                                                                     60, 80, 100};

/// One finding: its cause and its estimated error per axis (LSB: mN, 10 µN·m).
struct HealthFinding {
  HealthCause cause = HealthCause::kNone;
  WrenchLsb error_lsb{};
};

/// The watch's published state (copied with every published sample).
struct HealthReport {
  Ne107State state = Ne107State::kNormal;
  std::uint16_t findings = 0;  ///< bit (cause − 1) per active finding
  /// bit (cause − 1) per cause the watch could judge within the last hour (enough still holds,
  /// unloaded spells, temperature change, ringing steps, quiet blocks): "no finding" from
  /// "could not look".
  std::uint16_t coverage = 0;
  bool retare_suggested = false;
  HealthCause retare_reason = HealthCause::kNone;
  std::array<HealthFinding, kHealthSlots> slots{};  ///< active findings, cause order
  WrenchLsb zero_drift_lsb{};          ///< last unloaded zero since the tare / calibration, LSB
  std::int32_t mains50_bp = 0;         ///< worst axis 50 Hz amplitude, 0.01 % of rated
  std::int32_t mains60_bp = 0;         ///< the same at 60 Hz
  std::int32_t noise_ratio_pct = 0;    ///< worst axis noise ÷ commissioning noise, %
  std::int32_t ring_mhz = 0;           ///< last ringing frequency measured, mHz (0: none yet)
  std::int32_t ring_ref_mhz = 0;       ///< its commissioning value, mHz (0: not known yet)
  std::int32_t creep_bp = 0;           ///< last hold's creep, 0.01 % of its step
  std::int32_t thermal_ppm_per_k = 0;  ///< worst axis zero change per kelvin, ppm of rated
  std::uint32_t zero_points = 0;       ///< unloaded zero points since the tare / calibration
  std::uint32_t tare_age_s = 0;        ///< since the last tare (or start)
  std::int32_t tare_temp_mdegc = 0;    ///< temperature at the last tare (0 without one)
  std::uint16_t tare_count = 0;        ///< tares since start
  std::array<TareRecord, kTareHistory> tares{};  ///< the last tares, newest first
  /// Rainflow full cycles of the untared load per axis with a range ≥ 10 % of rated.
  std::array<std::uint32_t, kAxes> cycles{};
  /// Rainflow full cycles of the untared load per axis and range bin (kRainflowBinEdgesPct).
  std::array<std::array<std::uint32_t, kRainflowBins>, kAxes> cycle_bins{};
};

}  // namespace ftstack::fw
