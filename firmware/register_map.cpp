#include "firmware/register_map.hpp"

#include <sched.h>

#include <algorithm>
#include <bit>
#include <limits>

#include "firmware/fixed_point.hpp"
#include "firmware/health_registers.hpp"

namespace ftstack::fw {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

[[nodiscard]] bool HoldingMapped(std::uint32_t a) { return a < kHoldingRegisterSpan; }
[[nodiscard]] bool HoldingMount(std::uint32_t a) { return a >= kHoldMount && a < kHoldMount + 12u; }

[[nodiscard]] ToolTransformParams ParamsOf(const std::array<std::uint16_t, 12>& regs) {
  ToolTransformParams p{};
  for (std::size_t i = 0; i < 3; ++i) {
    p.d_m[i] = UnpackFloat32(&regs[2 * i]);
    p.r_deg[i] = UnpackFloat32(&regs[6 + 2 * i]);
  }
  return p;
}

/// Holding registers 5 … 9 and 29: reserved. They read 0 and accept 0 (so that a PLC's block
/// read or write of 0 … 29 works); any other value is refused with 03.
[[nodiscard]] bool HoldingReserved(std::uint32_t a) {
  return (a > kHoldUnlock && a < kHoldTransform) || a == kHoldReserved29 ||
         (a >= kHoldReserved42 && a < kHoldHealthCommand);
}

[[nodiscard]] bool HoldingHealth(std::uint32_t a) {
  return a >= kHoldHealthCommand && a < kHoldHealthEnd;
}

[[nodiscard]] bool InGravity(std::uint32_t a) { return a >= kHoldGravity && a < kHoldGravity + 6u; }

/// A write [addr, end) touching the float block [first, first + 2·floats) covers whole floats.
[[nodiscard]] bool WholeFloats(std::uint32_t addr, std::uint32_t end, std::uint32_t first,
                               std::uint32_t floats) {
  const std::uint32_t block_end = first + 2u * floats;
  const std::uint32_t lo = addr > first ? addr : first;
  const std::uint32_t hi = end < block_end ? end : block_end;
  return (lo - first) % 2 == 0 && (hi - first) % 2 == 0;
}

[[nodiscard]] float LsbToSi(std::int32_t v, std::size_t axis) {
  return static_cast<float>(static_cast<double>(v) * AxisLsb(axis));
}

}  // namespace

void PackU32(std::uint32_t v, std::uint16_t* regs) {
  regs[0] = static_cast<std::uint16_t>(v >> 16);
  regs[1] = static_cast<std::uint16_t>(v & 0xFFFFu);
}
void PackI32(std::int32_t v, std::uint16_t* regs) { PackU32(static_cast<std::uint32_t>(v), regs); }
void PackFloat32(float v, std::uint16_t* regs) { PackU32(std::bit_cast<std::uint32_t>(v), regs); }
std::uint32_t UnpackU32(const std::uint16_t* regs) {
  return (static_cast<std::uint32_t>(regs[0]) << 16) | regs[1];
}
std::int32_t UnpackI32(const std::uint16_t* regs) {
  return static_cast<std::int32_t>(UnpackU32(regs));
}
float UnpackFloat32(const std::uint16_t* regs) { return std::bit_cast<float>(UnpackU32(regs)); }

void BuildInputRegisters(const DeviceSample& d, const hal::AdcInfo& adc, std::uint64_t now_us,
                         std::uint64_t last_sample_us,
                         std::array<std::uint16_t, kInputRegisterCount>* regs) {
  auto& r = *regs;
  r = {};
  const PublishedSample& s = d.sample;
  std::uint16_t status = s.status;
  if (now_us > last_sample_us &&
      now_us - last_sample_us > static_cast<std::uint64_t>(d.stale_after_us)) {
    status |= kStatusStale;
  }
  r[kInMapVersion] = kMapVersion;
  r[kInStatus] = status;
  PackU32(s.sequence, &r[kInSequence]);
  PackU32(s.timestamp_us, &r[kInTimestampUs]);
  // No valid calibration, or no valid measurement (a bridge at its rail, clipped arithmetic):
  // the wrench registers read NaN and 0, never a held or clipped value.
  const bool cal_ok = (status & (kStatusCalInvalid | kStatusSaturated)) == 0;
  for (std::size_t i = 0; i < kAxes; ++i) {
    // An axis the calibration does not determine (status bit 10) is never a value either.
    const bool axis_ok = cal_ok && (s.invalid_axes & (1u << i)) == 0;
    const bool peak_ok = (d.peaks_invalid_axes & (1u << i)) == 0;
    PackFloat32(axis_ok ? LsbToSi(s.wrench[i], i) : kNaN, &r[kInWrenchFloat + 2 * i]);
    // Forces are already mN; moments go from 10 µN·m to mN·m, rounded to nearest.
    const std::int32_t v =
        i < 3 ? s.wrench[i]
              : static_cast<std::int32_t>(RoundDiv(s.wrench[i], kMomentLsbPerMilliNm));
    PackI32(axis_ok ? v : 0, &r[kInWrenchInt + 2 * i]);
    PackFloat32(peak_ok ? LsbToSi(d.peaks_lsb[i], i) : kNaN, &r[kInPeaks + 2 * i]);
  }
  PackFloat32(s.has_temperature ? static_cast<float>(s.temperature_mdegc * 1e-3) : kNaN,
              &r[kInTemperature]);
  // mV/V per count of this ADC; bridges beyond channel_count read 0 counts and NaN mV/V.
  const double mvv_per_count =
      adc.max_counts > 0 ? static_cast<double>(adc.full_scale_nvv) * 1e-6 / adc.max_counts : 0.0;
  for (std::size_t c = 0; c < kMapBridges; ++c) {
    const bool present = c < s.channel_count;
    PackI32(present ? s.raw_counts[c] : 0, &r[kInRawCounts + 2 * c]);
    PackFloat32(present ? static_cast<float>(s.raw_counts[c] * mvv_per_count) : kNaN,
                &r[kInBridgeMvv + 2 * c]);
  }
  r[kInBridgeCount] = s.channel_count;
  r[kInCalSlot] = d.cal_slot;
  PackU32(d.overload_events, &r[kInOverloadEvents]);
  PackU32(d.cal_crc, &r[kInCalCrc]);
  PackU32(d.late_samples, &r[kInLateSamples]);
  r[kInTimestampWraps] = s.timestamp_wraps;
  PackFloat32(static_cast<float>(static_cast<double>(d.payload_mass_ug) * 1e-9),
              &r[kInPayloadMass]);
  PackU32(d.payload_crc, &r[kInPayloadCrc]);
  BuildHealthInputRegisters(d, &r[kInHealthFirst]);
}

RegisterMap::RegisterMap(Device& device) : device_(device), settings_(device.initial_settings()) {}

bool RegisterMap::UnlockedLocked(std::uint64_t now_us) const {
  return unlock_armed_ && now_us < unlock_until_us_;
}

bool RegisterMap::Unlocked() {
  std::lock_guard<std::mutex> lock(mutex_);
  return UnlockedLocked(device_.NowUs());
}

void RegisterMap::ReadMqttInput(std::uint16_t* image) const {
  if (mqtt_ == nullptr) return;
  image[kInMqttConnected] =
      static_cast<std::uint16_t>(mqtt_->connected.load(std::memory_order_relaxed));
  PackU32(mqtt_->published.load(std::memory_order_relaxed), &image[kInMqttPublished]);
  PackU32(mqtt_->dropped.load(std::memory_order_relaxed), &image[kInMqttDropped]);
  PackU32(mqtt_->reconnects.load(std::memory_order_relaxed), &image[kInMqttReconnects]);
}

ModbusException RegisterMap::ReadInput(std::uint16_t addr, std::uint16_t count,
                                       std::uint16_t* out) {
  const std::uint32_t end = static_cast<std::uint32_t>(addr) + count;
  if (count == 0 || end > kInputAddressSpan) return ModbusException::kIllegalDataAddress;
  std::array<std::uint16_t, kInputAddressSpan> image{};
  if (addr < kInMqttFirst || end > kInHistoryFirst) {  // one sample for every sample register
    const ModbusException e = ReadSampleInput(image.data());
    if (e != ModbusException::kNone) return e;
  }
  if (addr < kInHistoryFirst && end > kInMqttFirst) ReadMqttInput(image.data());
  for (std::uint16_t i = 0; i < count; ++i) out[i] = image[addr + i];
  return ModbusException::kNone;
}

ModbusException RegisterMap::ReadSampleInput(std::uint16_t* image) {
  DeviceSample d{};
  // The writer may be preempted in the middle of a publication (odd sequence): let it run
  // rather than spinning. Only a writer stuck for 1000 scheduler rounds gives exception 04.
  bool got = device_.ReadLatest(&d);
  for (int round = 0; !got && round < 1000; ++round) {
    sched_yield();
    got = device_.ReadLatest(&d);
  }
  if (!got) return ModbusException::kDeviceFailure;
  std::array<std::uint16_t, kInputRegisterCount> main{};
  const std::uint64_t last_sample_us = device_.last_sample_us();
  BuildInputRegisters(d, device_.adc_info(), device_.NowUs(), last_sample_us, &main);
  std::copy(main.begin(), main.end(), image);
  BuildHealthHistoryRegisters(d, &image[kInHistoryFirst]);
  return ModbusException::kNone;
}

ModbusException RegisterMap::ReadHolding(std::uint16_t addr, std::uint16_t count,
                                         std::uint16_t* out) {
  if (count == 0) return ModbusException::kIllegalDataAddress;
  for (std::uint32_t a = addr; a < static_cast<std::uint32_t>(addr) + count; ++a) {
    if (!HoldingMapped(a)) return ModbusException::kIllegalDataAddress;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const bool unlocked = UnlockedLocked(device_.NowUs());
  for (std::uint16_t i = 0; i < count; ++i) {
    const std::uint32_t a = static_cast<std::uint32_t>(addr) + i;
    std::uint16_t v = 0;
    switch (a) {
      case kHoldCommand:
        v = 0;
        break;
      case kHoldFilterLength:
        v = settings_.filter_length;
        break;
      case kHoldDecimation:
        v = settings_.decimation;
        break;
      case kHoldCalSlot:
        v = settings_.cal_slot;
        break;
      case kHoldUnlock:
        v = unlocked ? 1 : 0;
        break;
      case kHoldGravityComp:
        v = settings_.gravity_comp ? 1 : 0;
        break;
      default:
        if (HoldingHealth(a)) {
          v = ReadHealthHolding(settings_, a);
        } else if (HoldingReserved(a)) {
          v = 0;
        } else if (InGravity(a)) {
          v = gravity_regs_[a - kHoldGravity];
        } else if (HoldingMount(a)) {
          v = mount_regs_[a - kHoldMount];
        } else {
          v = transform_regs_[a - kHoldTransform];
        }
        break;
    }
    out[i] = v;
  }
  return ModbusException::kNone;
}

ModbusException RegisterMap::WriteHolding(std::uint16_t addr, const std::uint16_t* values,
                                          std::uint16_t count, TareSource source) {
  const std::uint32_t end = static_cast<std::uint32_t>(addr) + count;
  if (count == 0) return ModbusException::kIllegalDataAddress;
  for (std::uint32_t a = addr; a < end; ++a) {
    if (!HoldingMapped(a)) return ModbusException::kIllegalDataAddress;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const std::uint64_t now_us = device_.NowUs();
  const bool unlocked = UnlockedLocked(now_us);
  DeviceSettings next = settings_;
  std::array<std::uint16_t, 12> next_transform = transform_regs_;
  std::array<std::uint16_t, 12> next_mount = mount_regs_;
  std::array<std::uint16_t, 6> next_gravity = gravity_regs_;
  bool transform_written = false;
  bool mount_written = false;
  bool gravity_written = false;
  bool unlock_written = false;
  for (std::uint32_t a = addr; a < end; ++a) {
    const std::uint16_t v = values[a - addr];
    switch (a) {
      case kHoldCommand:
        if (v == kCmdTare || v == kCmdClearTare) {
          ++next.tare_generation;
          next.tare_kind = static_cast<std::uint8_t>(v);
          next.tare_source = source;
        } else if (v == kCmdClearPeaks) {
          ++next.clear_generation;
        } else if (v != kCmdNone) {
          return ModbusException::kIllegalDataValue;
        }
        break;
      case kHoldFilterLength:
        if (v < 1 || v > kMaxFilterLength) return ModbusException::kIllegalDataValue;
        next.filter_length = v;
        break;
      case kHoldDecimation:
        if (v < 1 || v > kMaxDecimation) return ModbusException::kIllegalDataValue;
        next.decimation = v;
        break;
      case kHoldCalSlot:
        if (!unlocked || v >= kCalSlots || !device_.slot_present(v)) {
          return ModbusException::kIllegalDataValue;
        }
        next.cal_slot = static_cast<std::uint8_t>(v);
        break;
      case kHoldUnlock:
        if (v == 0) break;  // what the register reads while locked: no operation
        if (v != kUnlockKey) return ModbusException::kIllegalDataValue;
        unlock_written = true;
        break;
      case kHoldGravityComp:
        if (v > 1 || (v == 1 && !device_.payload_present())) {
          return ModbusException::kIllegalDataValue;
        }
        next.gravity_comp = v == 1;
        break;
      default:  // reserved, 10 … 21 tool transform, 22 … 27 gravity, 30 … 41 mount, 50 … 79 health
        if (HoldingHealth(a)) {  // not protected: thresholds and commissioning are the PLC's
          if (!WriteHealthHolding(a, v, &next)) return ModbusException::kIllegalDataValue;
          break;
        }
        if (HoldingReserved(a)) {
          if (v != 0) return ModbusException::kIllegalDataValue;
          break;
        }
        if (InGravity(a)) {  // not protected: a robot writes it as it moves
          next_gravity[a - kHoldGravity] = v;
          gravity_written = true;
          break;
        }
        if (!unlocked) return ModbusException::kIllegalDataValue;
        if (HoldingMount(a)) {
          next_mount[a - kHoldMount] = v;
          mount_written = true;
        } else {
          next_transform[a - kHoldTransform] = v;
          transform_written = true;
        }
        break;
    }
  }
  if (transform_written || mount_written) {
    // A float is two registers: a write must cover whole floats.
    if ((transform_written && !WholeFloats(addr, end, kHoldTransform, 6)) ||
        (mount_written && !WholeFloats(addr, end, kHoldMount, 6))) {
      return ModbusException::kIllegalDataValue;
    }
    if (MakeMountedToolTransform(ParamsOf(next_transform), ParamsOf(next_mount), &next.transform) !=
        TransformStatus::kOk) {
      return ModbusException::kIllegalDataValue;
    }
  }
  if (gravity_written) {
    if (!WholeFloats(addr, end, kHoldGravity, 3)) return ModbusException::kIllegalDataValue;
    for (std::size_t i = 0; i < 3; ++i) {
      if (!GravityToFixed(UnpackFloat32(&next_gravity[2 * i]), &next.gravity_umps2[i])) {
        return ModbusException::kIllegalDataValue;
      }
    }
  }
  // Everything validated: commit.
  settings_ = next;
  transform_regs_ = next_transform;
  mount_regs_ = next_mount;
  gravity_regs_ = next_gravity;
  if (unlock_written) {
    unlock_armed_ = true;
    unlock_until_us_ = now_us + kUnlockDurationUs;
  }
  device_.WriteSettings(settings_);
  return ModbusException::kNone;
}

}  // namespace ftstack::fw
