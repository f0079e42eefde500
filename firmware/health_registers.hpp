// The health watch's Modbus registers: input 100 … 199 and 210 … (history), holding 50 … 79.
#pragma once

#include <cstdint>

#include "firmware/device.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::fw {

/// Input register addresses of the health block (map version 3).
enum HealthInputRegister : std::uint16_t {
  kInHealthFirst = 100,
  kInHealthState = 100,     ///< Ne107State
  kInHealthFindings = 101,  ///< bit (cause − 1) per active finding
  kInRetareSuggested = 102,
  kInRetareReason = 103,   ///< HealthCause
  kInHealthWatchOn = 104,  ///< 1: the watch runs (it needs a rated range)
  kInFindingCause = 105,   ///< uint16 × 4: the active findings' causes, code order
  kInFindingError = 109,   ///< 4 × float32 × 6: each finding's error per axis, N and N·m
  kInZeroDrift = 157,      ///< float32 × 6, N and N·m
  kInThermalZero = 169,    ///< float32, worst axis zero per kelvin, % of rated per K
  kInMains50 = 171,        ///< float32, worst axis 50 Hz amplitude, % of rated
  kInMains60 = 173,        ///< float32, the same at 60 Hz
  kInNoiseRatio = 175,     ///< float32, worst axis noise ÷ commissioning noise
  kInRingHz = 177,         ///< float32, last ringing frequency (0: none yet)
  kInRingRefHz = 179,      ///< float32, commissioning ringing frequency (0: not known)
  kInCreepPct = 181,       ///< float32, last hold's creep, % of its load change
  kInZeroPoints = 183,     ///< uint32, zero points since the tare / calibration
  kInTareAge = 185,        ///< uint32, s since the last tare (or start)
  kInTareTemp = 187,       ///< float32 °C at the last tare (0 without one)
  kInTareCount = 189,      ///< uint16, tares since start
  kInCycles = 190,         ///< uint16 × 6, rainflow cycles ≥ 10 % of rated per axis (saturating)
  kInCoverage = 196,       ///< bit (cause − 1) per cause judged within the last hour
  kInHealthReserved = 197,  ///< 197 … 199 reserved, read 0
  kInHealthEnd = 200,
};

/// Input register addresses of the history block (map version 3, after the MQTT block).
enum HealthHistoryRegister : std::uint16_t {
  /// kTareHistory records of kTareRecordRegisters, newest first; per record at offset:
  /// 0 number (uint32, 0: empty), 2 source (uint16, TareSource), 3 reserved, 4 time_s (uint32),
  /// 6 temperature (float32 °C, NaN: none), 8 the load it removed (float32 × 6, N and N·m).
  kInTareHistory = 210,
  kInCycleBins = 290,  ///< uint32 × kRainflowBins per axis, Fx … Mz: rainflow full cycles per bin
  kInHistoryEnd = 386,
};
inline constexpr std::uint16_t kTareRecordRegisters = 20;
static_assert(kInTareHistory == kInHistoryFirst);
static_assert(kInTareHistory + kTareHistory * kTareRecordRegisters == kInCycleBins);
static_assert(kInCycleBins + kAxes * kRainflowBins * 2 == kInHistoryEnd);
static_assert(kInHistoryEnd == kInHistoryFirst + kInHistoryCount);

/// Holding register addresses of the health block: 50 command, 51 … 59 thresholds.
enum HealthHoldingRegister : std::uint16_t {
  kHoldHealthCommand = 50,  ///< 1 = commission, 2 = clear findings; reads 0
  kHoldHealthFirstThreshold = 51,
  kHoldHealthLastThreshold = 59,
  kHoldHealthEnd = 80,  ///< 60 … 79 reserved
};
enum HealthCommand : std::uint16_t { kHealthCmdCommission = 1, kHealthCmdClear = 2 };

/// Fills input registers 100 … 199 (regs points at address 100).
void BuildHealthInputRegisters(const DeviceSample& d, std::uint16_t* regs);
/// Fills the history block (regs points at address kInHistoryFirst).
void BuildHealthHistoryRegisters(const DeviceSample& d, std::uint16_t* regs);
/// The value holding register `a` (50 … 79) reads.
[[nodiscard]] std::uint16_t ReadHealthHolding(const DeviceSettings& s, std::uint32_t a);
/// Writes `v` to holding register `a` (50 … 79) of `next`; false (nothing written) when the value
/// is out of its range (exception 03).
[[nodiscard]] bool WriteHealthHolding(std::uint32_t a, std::uint16_t v, DeviceSettings* next);

}  // namespace ftstack::fw
