#include "firmware/device.hpp"

#include <algorithm>
#include <ctime>

namespace ftstack::fw {

std::uint64_t MonotonicUs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u +
         static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

DeviceStatus Device::Start(const DeviceConfig& config) {
  config_ = config;
  if (config.clock_us != nullptr) clock_ = config.clock_us;
  if (config.initial_slot >= kCalSlots) return DeviceStatus::kNoCalibration;
  const bool calibrated = config.slots[config.initial_slot].present;
  if (!calibrated && !config.allow_uncalibrated) return DeviceStatus::kNoCalibration;
  bool any_rated = false;
  for (const std::int32_t r : config.rated_lsb) any_rated = any_rated || r != 0;
  if (any_rated && !overload_.Configure(config.rated_lsb)) return DeviceStatus::kBadRated;
  // The ADC's conversion times count from its configuration: that instant is the samples' time
  // origin on the device clock.
  const std::uint64_t adc_start_us = clock_();
  if (sampler_.Start(config.adc) != hal::Status::kOk) return DeviceStatus::kAdcConfig;
  const std::uint32_t rate = sampler_.info().rate_hz > 0 ? sampler_.info().rate_hz : 1;
  sample_period_us_ = 1000000u / rate > 0 ? 1000000u / rate : 1u;
  const std::uint32_t block = sampler_.info().block_samples > 0 ? sampler_.info().block_samples : 1;
  // In 64 bits, saturated: a large block at a slow rate must not wrap the limits to small ones.
  const std::uint64_t late_after = std::uint64_t{block} * sample_period_us_;
  late_after_us_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(late_after, 0xFFFFFFFFu));
  stale_after_us_ = static_cast<std::uint32_t>(
      std::min<std::uint64_t>(late_after + sample_period_us_, 0xFFFFFFFFu));
  tare_samples_ = config.tare_samples;
  if (tare_samples_ == 0) {
    const std::uint32_t n = rate / 10;
    tare_samples_ =
        static_cast<std::uint16_t>(n < 1 ? 1 : (n > kMaxTareSamples ? kMaxTareSamples : n));
  }
  // Without a calibration the core gets an invalid one: bit 4, wrench registers NaN / 0.
  core_.SetCalibration(calibrated ? config.slots[config.initial_slot].fixed : FixedCalibration{});
  active_ = DeviceSettings{};
  active_.cal_slot = config.initial_slot;
  active_.filter_length = core_.filter_length();
  // The watch judges every threshold against the rated range: without one it stays off.
  if (config.health_watch) (void)health_.Configure(rate, config.rated_lsb);
  active_.health = health_.thresholds();
  initial_settings_ = active_;
  settings_.Write(active_);
  settings_seen_ = settings_.writes();
  tare_was_pending_ = false;
  last_ = DeviceSample{};
  last_.cal_slot = active_.cal_slot;
  last_.cal_crc = config.slots[active_.cal_slot].crc32;
  last_.publish_period_us = sample_period_us_;
  last_.sample_period_us = sample_period_us_;
  last_.stale_after_us = stale_after_us_;
  last_.publish_time_us = clock_();
  start_us_ = adc_start_us;
  stamped_ = false;
  last_stamp_us_ = 0;
  last_sample_us_.store(last_.publish_time_us, std::memory_order_release);
  gap_judged_ = false;
  late_samples_ = 0;
  last_.health_on = health_.configured();
  last_.sample.status = kStatusStale;  // nothing sampled yet
  published_.Write(last_);
  return DeviceStatus::kOk;
}

void Device::ApplySettings() {
  // The generation is taken before the copy: a write landing in between is either in the copy
  // (and applied again, harmlessly, next time: every field is idempotent, commands carry
  // generations) or after it (and seen next time). Taking it after the copy would mark a write
  // as seen that the copy does not hold — an acknowledged write lost.
  const std::uint32_t generation = settings_.writes();
  DeviceSettings s{};
  if (!settings_.Read(&s)) return;  // retried on the next sample
  settings_seen_ = generation;
  if (s.cal_slot != active_.cal_slot && s.cal_slot < kCalSlots &&
      config_.slots[s.cal_slot].present) {
    core_.SetCalibration(config_.slots[s.cal_slot].fixed);  // also clears tare and filter
    active_.cal_slot = s.cal_slot;
  }
  if (s.filter_length != active_.filter_length) {
    if (core_.SetFilterLength(s.filter_length)) active_.filter_length = s.filter_length;
  }
  if (s.decimation >= 1 && s.decimation <= kMaxDecimation) active_.decimation = s.decimation;
  active_.transform = s.transform;
  active_.gravity_umps2 = s.gravity_umps2;
  active_.gravity_comp = s.gravity_comp && config_.payload.present;
  if (s.tare_generation != active_.tare_generation) {
    active_.tare_generation = s.tare_generation;
    if (s.tare_kind == 1) {
      (void)core_.RequestTare(tare_samples_);  // tare_samples_ is within range by construction
      tare_source_ = s.tare_source;
    } else if (s.tare_kind == 2) {
      core_.ClearTare();
      health_.OnTare(last_.sample.temperature_mdegc, last_.sample.has_temperature, true);
    }
  }
  if (!(s.health == active_.health)) {
    active_.health = s.health;
    health_.SetThresholds(s.health);
  }
  if (s.health_generation != active_.health_generation) {
    active_.health_generation = s.health_generation;
    if (s.health_command == 1) health_.Commission();
    if (s.health_command == 2) health_.Clear();
  }
  if (s.clear_generation != active_.clear_generation) {
    active_.clear_generation = s.clear_generation;
    overload_.Clear();
  }
}

void Device::WatchHealth(const PublishedSample& p, std::uint16_t status) {
  if (!health_.configured()) return;
  const CoreOutput& core = sampler_.core_output();
  const bool pending = core_.tare_pending();
  if (tare_was_pending_ && !pending && core_.tare_active()) {
    health_.OnTare(p.temperature_mdegc, p.has_temperature, false, core_.tare_offset(),
                   tare_source_);
  }
  tare_was_pending_ = pending;
  HealthInput in;
  in.tared = core.unfiltered;
  in.untared = core.structural;
  in.untared_valid = core.structural_valid;
  in.valid =
      core.updated && !core.arithmetic_saturated &&
      (status & (kStatusSaturated | kStatusCalInvalid | kStatusBridgeFault | kStatusAdcFault)) == 0;
  in.temperature_mdegc = p.temperature_mdegc;
  in.has_temperature = p.has_temperature;
  in.status = status;
  in.tare_pending = pending;
  health_.Step(in);
}

void Device::JudgeTiming(PublishedSample* p, std::uint64_t now_us) {
  // The sample's time is when it converted, as the ADC reports it (µs since its configuration,
  // which is start_us_ on the device clock): a sampler that reads a block at once, or falls
  // behind, does not move it. Strictly increasing: a converter stamping two samples within one
  // microsecond gives the second one microsecond more.
  std::uint64_t since_start_us =
      (static_cast<std::uint64_t>(p->timestamp_wraps) << 32) | p->timestamp_us;
  if (stamped_ && since_start_us <= last_stamp_us_) since_start_us = last_stamp_us_ + 1;
  const std::uint64_t previous_us = last_stamp_us_;
  stamped_ = true;
  last_stamp_us_ = since_start_us;
  p->timestamp_us = static_cast<std::uint32_t>(since_start_us);
  p->timestamp_wraps = static_cast<std::uint16_t>(since_start_us >> 32);
  // A virtual timeline (the unpaced simulator) has no place on the clock: its samples count as
  // converted when read.
  const bool on_clock = sampler_.info().clock_timestamps;
  const std::uint64_t converted_us = on_clock ? start_us_ + since_start_us : now_us;
  last_sample_us_.store(converted_us, std::memory_order_release);
  // Missed deadlines, judged on conversion times: conversions more than 1.5 periods apart lost
  // the periods in between (a converter stamping at data-ready shows a sampler that fell behind
  // this way), and a sample read more than one block after it converted was late itself.
  std::uint64_t missed = 0;
  if (gap_judged_ && since_start_us - previous_us > 3ull * sample_period_us_ / 2) {
    missed = (since_start_us - previous_us + sample_period_us_ / 2) / sample_period_us_ - 1;
  }
  gap_judged_ = true;
  if (now_us > converted_us && now_us - converted_us > late_after_us_) ++missed;
  if (missed == 0) return;
  late_samples_ = missed > 0xFFFFFFFFull - late_samples_
                      ? 0xFFFFFFFFu
                      : late_samples_ + static_cast<std::uint32_t>(missed);
  sticky_status_ |= kStatusLate;
}

hal::Status Device::Step(bool* published) {
  *published = false;
  if (settings_.writes() != settings_seen_) ApplySettings();
  PublishedSample p{};
  const hal::Status s = sampler_.Step(p);
  if (s == hal::Status::kEndOfData) return s;
  if (s != hal::Status::kOk) {
    // The gap a backend fault leaves is that fault's (bits 3 and 8), not a late sampler.
    gap_judged_ = false;
    // Publish the fault bits at once; the wrench and sequence stay those of the last sample.
    last_.sample.status = p.status;
    published_.Write(last_);
    *published = true;
    return s;
  }
  ++samples_;
  const std::uint64_t now_us = clock_();
  JudgeTiming(&p, now_us);
  const CoreOutput& core = sampler_.core_output();
  // Overload and peaks judge the load the body carries: untared, also while a bridge saturates.
  if (core.structural_valid && overload_.configured()) {
    if (overload_.Update(core.structural, core.saturated_by_load)) {
      sticky_status_ |= kStatusOverload;
    }
  }
  // A wrench clipped by the arithmetic is not a measurement: flag it like a saturated bridge.
  if (core.arithmetic_saturated) sticky_status_ |= kStatusSaturated;
  WatchHealth(p, static_cast<std::uint16_t>(p.status | sticky_status_));
  if (++since_publish_ < active_.decimation) return s;
  since_publish_ = 0;

  DeviceSample d{};
  d.sample = p;
  d.sample.sequence = ++publish_sequence_;
  std::uint16_t status = static_cast<std::uint16_t>(p.status | sticky_status_);
  sticky_status_ = 0;
  if ((status & kStatusCalInvalid) == 0) {
    bool sat = false;
    WrenchLsb sensor = p.wrench;
    if (active_.gravity_comp) {  // payload weight and moment off, in the sensor frame
      CompensateGravity(config_.payload, active_.gravity_umps2, p.wrench, &sensor, &sat);
      status |= kStatusPayloadComp;
    }
    ApplyToolTransform(active_.transform, sensor, &d.sample.wrench, &sat);
    if (sat) status |= kStatusSaturated;  // the tool-frame wrench was clipped
    // An axis the calibration does not determine taints every tool-frame axis it enters.
    d.sample.invalid_axes = ToolFrameInvalidAxes(active_.transform, p.invalid_axes);
    for (std::size_t i = 0; i < kAxes; ++i) {
      if ((d.sample.invalid_axes & (1u << i)) != 0) d.sample.wrench[i] = 0;
    }
  }
  d.peaks_invalid_axes = p.invalid_axes;
  if (p.has_temperature && (p.temperature_mdegc < config_.temp_min_mdegc ||
                            p.temperature_mdegc > config_.temp_max_mdegc)) {
    status |= kStatusTempRange;
  }
  d.sample.status = status;
  d.peaks_lsb = overload_.peaks();
  d.overload_events = overload_.events();
  d.cal_slot = active_.cal_slot;
  d.cal_crc = config_.slots[active_.cal_slot].crc32;
  d.publish_period_us = sample_period_us_ * active_.decimation;
  d.sample_period_us = sample_period_us_;
  d.stale_after_us = stale_after_us_;
  d.late_samples = late_samples_;
  d.payload_mass_ug = config_.payload.present ? config_.payload.mass_ug : 0;
  d.payload_crc = config_.payload_crc;
  d.publish_time_us = now_us;
  d.health = health_.report();
  d.health_on = health_.configured();
  last_ = d;
  published_.Write(d);
  *published = true;
  return s;
}

}  // namespace ftstack::fw
