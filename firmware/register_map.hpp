// The Modbus register map, version 3 (docs/spec/modbus-map.md): input image, holding registers.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>

#include "firmware/device.hpp"

namespace ftstack::fw {

inline constexpr std::uint16_t kMapVersion = 3;
/// Input registers 0 … 199 (the sample's image): 81 … 99 reserved, 100 … 199 the health watch
/// (health_registers.hpp); the MQTT block 200 … 209 follows (MqttInputRegister), then the history
/// block 210 … (kInHistoryFirst).
inline constexpr std::uint16_t kInputRegisterCount = 200;
/// Input registers 0 … 84, map version 2's image: one read covers it (a Modbus read carries at
/// most 125 registers; the whole v3 image takes two).
inline constexpr std::uint16_t kInputRegistersV2 = 85;
/// Holding 0 … 79: 5 … 9, 29 and 42 … 49 reserved; 50 … 79 the health watch.
inline constexpr std::uint16_t kHoldingRegisterSpan = 80;

/// Input register addresses (0-based protocol addresses).
enum InputRegister : std::uint16_t {
  kInMapVersion = 0,
  kInStatus = 1,
  kInSequence = 2,      ///< uint32
  kInTimestampUs = 4,   ///< uint32
  kInWrenchFloat = 6,   ///< float32 × 6, N and N·m
  kInWrenchInt = 18,    ///< int32 × 6, mN and mN·m
  kInTemperature = 30,  ///< float32 °C, NaN where none
  kInRawCounts = 32,    ///< int32 × 6
  kInBridgeMvv = 44,    ///< float32 × 6
  kInBridgeCount = 56,
  kInCalSlot = 57,
  kInOverloadEvents = 58,  ///< uint32
  kInPeaks = 60,           ///< float32 × 6, N and N·m
  kInCalCrc = 72,          ///< uint32
  kInLateSamples = 74,     ///< uint32, missed sampling deadlines since start
  kInTimestampWraps = 76,  ///< uint16, wraps of the 32-bit µs timestamp (its bits 32–47)
  kInPayloadMass = 77,     ///< float32 kg, payload of gravity compensation (0: none). Map v2
  kInPayloadCrc = 79,      ///< uint32, CRC-32 of the payload file (0: none). Map v2
  kInReserved81 = 81,      ///< 81 … 84 reserved, read 0. Map v2
  kInReserved85 = 85,      ///< 85 … 99 reserved, read 0. Map v3
};

/// The MQTT block of input registers, 200–209 (map v3): a second range of the input table.
enum MqttInputRegister : std::uint16_t {
  kInMqttFirst = 200,
  kInMqttConnected = 200,    ///< uint16, 1 while connected to the broker
  kInMqttPublished = 201,    ///< uint32
  kInMqttDropped = 203,      ///< uint32
  kInMqttReconnects = 205,   ///< uint32
  kInMqttReserved207 = 207,  ///< 207 … 209 reserved, read 0
};
inline constexpr std::uint16_t kInMqttCount = 10;
/// The history block of input registers, 210 … (map v3, after the MQTT block): the tare history
/// and the rainflow range bins, from the same published sample as 0 … 199 (layout:
/// health_registers.hpp).
inline constexpr std::uint16_t kInHistoryFirst = kInMqttFirst + kInMqttCount;
inline constexpr std::uint16_t kInHistoryCount = 176;
/// Input addresses 0 … kInputAddressSpan − 1: the sample image, the MQTT block and the history
/// block (the server's table size).
inline constexpr std::uint16_t kInputAddressSpan = kInHistoryFirst + kInHistoryCount;
static_assert(kInMqttFirst == kInputRegisterCount, "the MQTT block follows the sample image");

/// Holding register addresses.
enum HoldingRegister : std::uint16_t {
  kHoldCommand = 0,
  kHoldFilterLength = 1,
  kHoldDecimation = 2,
  kHoldCalSlot = 3,  ///< protected
  kHoldUnlock = 4,
  kHoldTransform = 10,    ///< float32 × 6 (Dx Dy Dz m, Rx Ry Rz deg), protected, 10 … 21
  kHoldGravity = 22,      ///< float32 × 3, gravity in the sensor frame, m/s², 22 … 27. Map v2
  kHoldGravityComp = 28,  ///< 0 off, 1 on (needs a payload). Map v2
  kHoldReserved29 = 29,   ///< reserved, reads 0. Map v2
  kHoldMount = 30,  ///< float32 × 6 mount transform (same layout), protected, 30 … 41. Map v2
  kHoldReserved42 = 42,  ///< 42 … 49 reserved, read 0. Map v3
};

/// Values of the command register.
/// Values of the command register (0: no command, what the register reads back).
enum Command : std::uint16_t { kCmdNone = 0, kCmdTare = 1, kCmdClearTare = 2, kCmdClearPeaks = 3 };

inline constexpr std::uint16_t kUnlockKey = 0xA5C3;
inline constexpr std::uint64_t kUnlockDurationUs = 10'000'000;
/// Number of registers of the bridge blocks (raw counts, mV/V): 6 bridges.
inline constexpr std::size_t kMapBridges = 6;

/// Modbus exception codes the map produces (0: none).
enum class ModbusException : std::uint8_t {
  kNone = 0,
  kIllegalFunction = 1,
  kIllegalDataAddress = 2,
  kIllegalDataValue = 3,
  kDeviceFailure = 4,  ///< the latest sample could not be copied (writer starved the reader)
};

/// Counters of ftd's MQTT publisher (a daemon thread outside the firmware), served in input
/// registers 200–209 once set with RegisterMap::SetMqttCounters; all 0 without MQTT.
struct MqttCounters {
  std::atomic<std::uint32_t> connected{0};   ///< 1 while a broker connection is up
  std::atomic<std::uint32_t> published{0};   ///< messages handed to the broker, wraps
  std::atomic<std::uint32_t> dropped{0};     ///< wrench windows never published, wraps
  std::atomic<std::uint32_t> reconnects{0};  ///< connections after the first
};

/// 32-bit values over two registers, high word first (the map's "ABCD" order). Written here
/// rather than with modbus_set_float_* (which does not round-trip in libmodbus 3.1.6).
void PackU32(std::uint32_t v, std::uint16_t* regs);
void PackI32(std::int32_t v, std::uint16_t* regs);
void PackFloat32(float v, std::uint16_t* regs);
[[nodiscard]] std::uint32_t UnpackU32(const std::uint16_t* regs);
[[nodiscard]] std::int32_t UnpackI32(const std::uint16_t* regs);
[[nodiscard]] float UnpackFloat32(const std::uint16_t* regs);

/// Fills the whole input image from one published sample. The stale bit is set when the latest
/// sample read (`last_sample_us`, device clock, also samples not published because of
/// decimation) is more than two sample periods older than `now_us`.
void BuildInputRegisters(const DeviceSample& d, const hal::AdcInfo& adc, std::uint64_t now_us,
                         std::uint64_t last_sample_us,
                         std::array<std::uint16_t, kInputRegisterCount>* regs);

/// The slave's view of one Device: reads build replies from one published sample; writes are
/// validated completely before anything changes. Thread-safe (TCP and RTU servers share one map).
class RegisterMap {
 public:
  explicit RegisterMap(Device& device);

  /// Function 04. 02 when [addr, addr+count) leaves 0 … kInputAddressSpan − 1 (a read may span
  /// the blocks; the sample's registers of one reply come from one sample); reserved 81 … 99,
  /// 197 … 199 and 207 … 209 read 0.
  [[nodiscard]] ModbusException ReadInput(std::uint16_t addr, std::uint16_t count,
                                          std::uint16_t* out);
  /// Function 03. 02 when any address is outside 0 … 79; reserved 5 … 9, 29, 42 … 49 and 60 … 79
  /// read 0.
  [[nodiscard]] ModbusException ReadHolding(std::uint16_t addr, std::uint16_t count,
                                            std::uint16_t* out);
  /// Functions 06 and 16. 02 for an address outside the map; 03 for a value out of range, an
  /// unknown command, a non-zero value in a reserved register (5–9, 29, 42–49, 60–79), a health
  /// threshold (51–59) outside its range, a protected register (3,
  /// 10–21, 30–41) while locked, a write covering only one half of a float (10–27, 30–41), a
  /// gravity component that is not finite or beyond ±20 m/s², or gravity compensation on (28 = 1)
  /// without a payload. On any exception nothing changes.
  /// `source` says who wrote (a tare command is recorded with it in the tare history).
  [[nodiscard]] ModbusException WriteHolding(std::uint16_t addr, const std::uint16_t* values,
                                             std::uint16_t count,
                                             TareSource source = TareSource::kModbus);

  /// True while protected writes are allowed (within 10 s of writing kUnlockKey).
  [[nodiscard]] bool Unlocked();
  [[nodiscard]] Device& device() { return device_; }
  /// Serves `counters` in input registers 200–209 (they read 0 until set); set once, before the
  /// servers start.
  void SetMqttCounters(const MqttCounters* counters) { mqtt_ = counters; }

 private:
  /// Input registers 0 … kInputRegisterCount − 1 and the history block of `image` (the whole
  /// input table) from the latest published sample.
  [[nodiscard]] ModbusException ReadSampleInput(std::uint16_t* image);
  /// The MQTT block of `image` (the whole input table).
  void ReadMqttInput(std::uint16_t* image) const;

  [[nodiscard]] bool UnlockedLocked(std::uint64_t now_us) const;

  std::mutex mutex_;
  Device& device_;
  DeviceSettings settings_{};
  std::array<std::uint16_t, 12> transform_regs_{};
  std::array<std::uint16_t, 12> mount_regs_{};
  std::array<std::uint16_t, 6> gravity_regs_{};
  std::uint64_t unlock_until_us_ = 0;
  const MqttCounters* mqtt_ = nullptr;
  bool unlock_armed_ = false;
};

}  // namespace ftstack::fw
