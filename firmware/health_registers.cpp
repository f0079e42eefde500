#include "firmware/health_registers.hpp"

#include <limits>

#include "firmware/register_map.hpp"

namespace ftstack::fw {
namespace {

/// One threshold register: its field and its accepted raw range.
struct ThresholdRegister {
  std::uint16_t HealthThresholds::*field;
  std::uint16_t min;
  std::uint16_t max;
};
constexpr ThresholdRegister kThresholds[] = {
    {&HealthThresholds::zero_window_bp, 1, 1000},     // 51: 0.01 … 10 % of rated
    {&HealthThresholds::zero_limit_bp, 1, 1000},      // 52
    {&HealthThresholds::stability_bp, 1, 1000},       // 53
    {&HealthThresholds::stable_time_ds, 1, 600},      // 54: 0.1 … 60 s
    {&HealthThresholds::mains_limit_bp, 1, 1000},     // 55
    {&HealthThresholds::noise_factor_d, 11, 1000},    // 56: 1.1 … 100 ×
    {&HealthThresholds::resonance_shift_pm, 5, 500},  // 57: 0.5 … 50 %
    {&HealthThresholds::creep_limit_bp, 1, 1000},     // 58
    {&HealthThresholds::ring_ref_dhz, 0, 20000},      // 59: 0 (learn) … 2 kHz
};
static_assert(sizeof(kThresholds) / sizeof(kThresholds[0]) ==
              kHoldHealthLastThreshold - kHoldHealthFirstThreshold + 1);

[[nodiscard]] float LsbToSi(std::int32_t v, std::size_t axis) {
  return static_cast<float>(static_cast<double>(v) * AxisLsb(axis));
}

void PackWrench(const WrenchLsb& w, std::uint16_t* regs) {
  for (std::size_t r = 0; r < kAxes; ++r) PackFloat32(LsbToSi(w[r], r), &regs[2 * r]);
}

}  // namespace

void BuildHealthInputRegisters(const DeviceSample& d, std::uint16_t* regs) {
  const HealthReport& h = d.health;
  auto at = [regs](std::uint16_t address) { return &regs[address - kInHealthFirst]; };
  *at(kInHealthState) = static_cast<std::uint16_t>(h.state);
  *at(kInHealthFindings) = h.findings;
  *at(kInRetareSuggested) = h.retare_suggested ? 1 : 0;
  *at(kInRetareReason) = static_cast<std::uint16_t>(h.retare_reason);
  *at(kInHealthWatchOn) = d.health_on ? 1 : 0;
  for (std::size_t k = 0; k < kHealthSlots; ++k) {
    *at(static_cast<std::uint16_t>(kInFindingCause + k)) =
        static_cast<std::uint16_t>(h.slots[k].cause);
    PackWrench(h.slots[k].error_lsb, at(static_cast<std::uint16_t>(kInFindingError + 12 * k)));
  }
  PackWrench(h.zero_drift_lsb, at(kInZeroDrift));
  PackFloat32(static_cast<float>(h.thermal_ppm_per_k * 1e-4), at(kInThermalZero));
  PackFloat32(static_cast<float>(h.mains50_bp * 1e-2), at(kInMains50));
  PackFloat32(static_cast<float>(h.mains60_bp * 1e-2), at(kInMains60));
  PackFloat32(static_cast<float>(h.noise_ratio_pct * 1e-2), at(kInNoiseRatio));
  PackFloat32(static_cast<float>(h.ring_mhz * 1e-3), at(kInRingHz));
  PackFloat32(static_cast<float>(h.ring_ref_mhz * 1e-3), at(kInRingRefHz));
  PackFloat32(static_cast<float>(h.creep_bp * 1e-2), at(kInCreepPct));
  PackU32(h.zero_points, at(kInZeroPoints));
  PackU32(h.tare_age_s, at(kInTareAge));
  PackFloat32(static_cast<float>(h.tare_temp_mdegc * 1e-3), at(kInTareTemp));
  *at(kInTareCount) = h.tare_count;
  *at(kInCoverage) = h.coverage;
  for (std::size_t r = 0; r < kAxes; ++r) {
    *at(static_cast<std::uint16_t>(kInCycles + r)) =
        static_cast<std::uint16_t>(h.cycles[r] > 0xFFFFu ? 0xFFFFu : h.cycles[r]);
  }
}

void BuildHealthHistoryRegisters(const DeviceSample& d, std::uint16_t* regs) {
  for (std::size_t k = 0; k < kTareHistory; ++k) {
    const TareRecord& t = d.health.tares[k];
    std::uint16_t* r = &regs[kInTareHistory - kInHistoryFirst + k * kTareRecordRegisters];
    if (t.number == 0) continue;  // an empty slot reads 0
    PackU32(t.number, &r[0]);
    r[2] = static_cast<std::uint16_t>(t.source);
    PackU32(t.time_s, &r[4]);
    PackFloat32(t.has_temperature ? static_cast<float>(t.temperature_mdegc * 1e-3)
                                  : std::numeric_limits<float>::quiet_NaN(),
                &r[6]);
    PackWrench(t.load_lsb, &r[8]);
  }
  std::uint16_t* bins = &regs[kInCycleBins - kInHistoryFirst];
  for (std::size_t a = 0; a < kAxes; ++a) {
    for (std::size_t k = 0; k < kRainflowBins; ++k) {
      PackU32(d.health.cycle_bins[a][k], &bins[2 * (a * kRainflowBins + k)]);
    }
  }
}

std::uint16_t ReadHealthHolding(const DeviceSettings& s, std::uint32_t a) {
  if (a < kHoldHealthFirstThreshold || a > kHoldHealthLastThreshold) return 0;  // command, reserved
  return s.health.*kThresholds[a - kHoldHealthFirstThreshold].field;
}

bool WriteHealthHolding(std::uint32_t a, std::uint16_t v, DeviceSettings* next) {
  if (a == kHoldHealthCommand) {
    if (v == 0) return true;
    if (v != kHealthCmdCommission && v != kHealthCmdClear) return false;
    ++next->health_generation;
    next->health_command = static_cast<std::uint8_t>(v);
    return true;
  }
  if (a < kHoldHealthFirstThreshold || a > kHoldHealthLastThreshold) return v == 0;  // reserved
  const ThresholdRegister& t = kThresholds[a - kHoldHealthFirstThreshold];
  if (v < t.min || v > t.max) return false;
  next->health.*t.field = v;
  return true;
}

}  // namespace ftstack::fw
