// The sensor device: sampling step (ADC → core → transform, overload) publishing the latest sample.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "firmware/core.hpp"
#include "firmware/gravity_comp.hpp"
#include "firmware/health_watch.hpp"
#include "firmware/overload.hpp"
#include "firmware/sampler.hpp"
#include "firmware/seqlock.hpp"
#include "firmware/tool_transform.hpp"

namespace ftstack::fw {

/// Number of calibration slots (Modbus holding register 3).
inline constexpr std::size_t kCalSlots = 2;

/// What the Modbus side and the logger read: one published sample plus the device's counters, all
/// from the same instant.
struct DeviceSample {
  PublishedSample sample{};  ///< sequence +1 per published sample; wrench in the tool frame
  WrenchLsb peaks_lsb{};     ///< peak |component| since the last clear, sensor frame, LSB
  std::uint32_t overload_events = 0;
  std::uint32_t cal_crc = 0;            ///< CRC-32 of the active calibration slot
  std::uint8_t cal_slot = 0;            ///< active calibration slot
  std::uint64_t publish_time_us = 0;    ///< device clock at the last successful publication
  std::uint32_t publish_period_us = 0;  ///< expected time between publications
  std::uint32_t sample_period_us = 0;   ///< expected time between samples
  /// Stale limit: the newest sample converted more than this long ago (one ADC block and one
  /// period: a block's first sample waits for its last).
  std::uint32_t stale_after_us = 0;
  std::uint32_t late_samples = 0;       ///< samples read late since start (missed deadlines)
  std::int64_t payload_mass_ug = 0;     ///< payload of gravity compensation, µg (0: none)
  std::uint32_t payload_crc = 0;        ///< CRC-32 of its payload file (input registers 79–80)
  std::uint8_t peaks_invalid_axes = 0;  ///< bit r: peak r is not a value (sensor frame)
  HealthReport health{};                ///< the health watch (input registers 100 … 189)
  bool health_on = false;               ///< the watch runs (it needs a rated range)
};

/// One calibration slot as the device holds it.
struct CalSlot {
  FixedCalibration fixed{};
  std::uint32_t crc32 = 0;  ///< CRC-32 reported in input registers 72–73
  bool present = false;
};

/// Settings and commands written by the Modbus side, read by the sampling thread.
struct DeviceSettings {
  std::uint16_t filter_length = 1;  ///< 1 … kMaxFilterLength
  std::uint16_t decimation = 1;     ///< publish every N-th sample, 1 … kMaxDecimation
  std::uint8_t cal_slot = 0;
  FixedToolTransform transform{};
  std::uint32_t tare_generation = 0;            ///< +1 per tare / clear-tare command
  std::uint8_t tare_kind = 0;                   ///< 1 = tare now, 2 = clear tare (the latest wins)
  TareSource tare_source = TareSource::kNone;   ///< who asked for the latest tare command
  std::uint32_t clear_generation = 0;           ///< +1 per "clear peaks and overload counter"
  std::array<std::int32_t, 3> gravity_umps2{};  ///< gravity in the sensor frame, µm/s²
  bool gravity_comp = false;                    ///< subtract the payload (needs one)
  HealthThresholds health{};                    ///< the health watch's thresholds
  std::uint32_t health_generation = 0;          ///< +1 per health command
  std::uint8_t health_command = 0;  ///< 1 = commission, 2 = clear findings (the latest wins)
};

inline constexpr std::uint16_t kMaxDecimation = 1000;

/// Static configuration of a Device.
struct DeviceConfig {
  hal::AdcConfig adc{};
  std::array<CalSlot, kCalSlots> slots{};
  std::uint8_t initial_slot = 0;
  WrenchLsb rated_lsb{};            ///< rated range per axis (overload rule); zeros disable it
  std::int32_t temp_min_mdegc = 0;  ///< compensated temperature range (status bit 6)
  std::int32_t temp_max_mdegc = 50000;
  std::uint16_t tare_samples = 0;         ///< samples averaged by a tare; 0: rate/10 (0.1 s)
  std::uint64_t (*clock_us)() = nullptr;  ///< monotonic µs; nullptr: CLOCK_MONOTONIC
  /// Start even when the initial slot holds no calibration: the device then samples and serves
  /// with kStatusCalInvalid and an invalid wrench (a field device comes up and says why).
  bool allow_uncalibrated = false;
  FixedPayload payload{};         ///< gravity compensation's payload (present: loaded)
  bool health_watch = true;       ///< run the health watch (it also needs rated_lsb)
  std::uint32_t payload_crc = 0;  ///< CRC-32 of the payload file
};

/// Why Device::Start failed.
enum class DeviceStatus : std::uint8_t { kOk = 0, kAdcConfig, kNoCalibration, kBadRated };

/// CLOCK_MONOTONIC in µs.
[[nodiscard]] std::uint64_t MonotonicUs();

/// The firmware main loop's data path. Step() runs in the sampling thread only; ReadLatest,
/// settings and commands may be used from any thread (settings writes from one thread at a time).
class Device {
 public:
  Device(hal::Adc& adc, WrenchCore& core) : adc_(adc), core_(core), sampler_(adc, core) {}

  [[nodiscard]] DeviceStatus Start(const DeviceConfig& config);

  /// Waits for, processes and (every decimation-th sample) publishes one sample. *published says
  /// whether this call published. kEndOfData when a replay ended; kTimeout / kReadError publish
  /// the fault bits with the last wrench (and do not refresh the publication time).
  [[nodiscard]] hal::Status Step(bool* published);

  /// The latest published sample (consistent copy). False only if the writer starved the reader.
  [[nodiscard]] bool ReadLatest(DeviceSample* out) const { return published_.Read(out); }
  /// The last sample Step published (sampling thread only).
  [[nodiscard]] const DeviceSample& last_published() const { return last_; }

  /// Hands new settings to the sampling thread (applied before its next sample).
  void WriteSettings(const DeviceSettings& s) { settings_.Write(s); }
  [[nodiscard]] const DeviceSettings& initial_settings() const { return initial_settings_; }

  [[nodiscard]] bool payload_present() const { return config_.payload.present; }
  [[nodiscard]] bool slot_present(std::size_t slot) const {
    return slot < kCalSlots && config_.slots[slot].present;
  }
  [[nodiscard]] const hal::AdcInfo& adc_info() const { return sampler_.info(); }
  [[nodiscard]] std::uint64_t NowUs() const { return clock_(); }
  [[nodiscard]] std::uint32_t sample_period_us() const { return sample_period_us_; }
  /// Samples processed by Step (successful reads).
  [[nodiscard]] std::uint64_t samples() const { return samples_; }
  /// Device clock at which the newest sample read converted (any thread): what "stale" is judged
  /// on.
  [[nodiscard]] std::uint64_t last_sample_us() const {
    return last_sample_us_.load(std::memory_order_acquire);
  }
  /// Missed sampling deadlines since start, judged on conversion times: a conversion more than
  /// 1.5 periods after the previous one counts the periods it skipped, a sample read more than
  /// one ADC block after its conversion counts one.
  [[nodiscard]] std::uint32_t late_samples() const { return late_samples_; }

 private:
  void ApplySettings();
  /// Feeds the health watch one processed sample (and tells it of a completed tare).
  void WatchHealth(const PublishedSample& p, std::uint16_t status);
  /// Gives the sample its conversion time since Start (strictly increasing) and applies the late
  /// rule to it, read at device time now_us.
  void JudgeTiming(PublishedSample* p, std::uint64_t now_us);

  hal::Adc& adc_;
  WrenchCore& core_;
  Sampler sampler_;
  DeviceConfig config_{};
  std::uint64_t (*clock_)() = &MonotonicUs;
  OverloadMonitor overload_{};
  HealthWatch health_{};
  bool tare_was_pending_ = false;
  TareSource tare_source_ = TareSource::kNone;  ///< who asked for the tare under way
  Seqlock<DeviceSample> published_{};
  Seqlock<DeviceSettings> settings_{};
  std::uint32_t settings_seen_ = 0;
  DeviceSettings active_{};
  DeviceSettings initial_settings_{};
  DeviceSample last_{};
  std::uint32_t sample_period_us_ = 1000;
  std::uint16_t tare_samples_ = 1;
  std::uint16_t since_publish_ = 0;
  std::uint16_t sticky_status_ = 0;
  std::uint32_t publish_sequence_ = 0;
  std::uint64_t samples_ = 0;
  std::atomic<std::uint64_t> last_sample_us_{0};
  std::uint64_t start_us_ = 0;       ///< device clock when the ADC was configured: the time origin
  std::uint64_t last_stamp_us_ = 0;  ///< time given to the previous sample, since Start
  bool stamped_ = false;
  bool gap_judged_ = false;  ///< the previous conversion counts for the gap rule (no fault since)
  std::uint32_t late_after_us_ = 1000;   ///< a sample read later than this after converting is late
  std::uint32_t stale_after_us_ = 2000;  ///< see DeviceSample::stale_after_us
  std::uint32_t late_samples_ = 0;
};

}  // namespace ftstack::fw
