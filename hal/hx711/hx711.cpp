#include "hal/hx711/hx711.hpp"

namespace ftstack::hal::hx711 {
namespace {

/// How long PD_SCK is held high to be sure every chip has powered down (datasheet: > 60 µs).
constexpr std::int64_t kPowerDownHoldNs = 100000;

[[nodiscard]] constexpr std::uint8_t Bit(std::size_t i) {
  return static_cast<std::uint8_t>(1u << i);
}

}  // namespace

Hx711Adc::Hx711Adc(const Hx711Params& params, gpio::Clock& clock)
    : params_(params), clock_(clock) {}

bool Hx711Adc::Pulse(gpio::OutputLine& clock, std::int64_t& width_ns) {
  // The bound includes both GPIO calls: the real high time can only be shorter. Sampling DOUT
  // after the falling edge keeps the high phase as short as the GPIO layer allows (DOUT changes on
  // the rising edge and stays valid until the next one).
  const std::int64_t t0 = clock_.NowNs();
  const Status up = clock.Set(true);
  const Status down = clock.Set(false);
  width_ns = clock_.NowNs() - t0;
  if (width_ns > longest_pulse_ns_) longest_pulse_ns_ = width_ns;
  return up == Status::kOk && down == Status::kOk;
}

void Hx711Adc::ResetGroups() {
  for (std::size_t g = 0; g < group_count_; ++g) {
    groups_[g].discard_left = params_.discard_after_reset;
  }
}

Status Hx711Adc::PowerDown() {
  if (!configured_) return Status::kNotConfigured;
  Status s = Status::kOk;
  for (std::size_t g = 0; g < group_count_; ++g) {
    if (groups_[g].clock->Set(true) != Status::kOk) s = Status::kReadError;
  }
  clock_.SleepNs(kPowerDownHoldNs);
  ready_ = false;
  return s;
}

Status Hx711Adc::PowerUp() {
  if (!configured_) return Status::kNotConfigured;
  Status s = Status::kOk;
  for (std::size_t g = 0; g < group_count_; ++g) {
    if (groups_[g].clock->Set(false) != Status::kOk) s = Status::kReadError;
  }
  ResetGroups();
  ready_ = false;
  return s;
}

Status Hx711Adc::DoConfigure(const AdcConfig& config) {
  configured_ = false;
  ready_ = false;
  const std::uint8_t n = config.channel_count;
  if (params_.chip_count > kMaxChannels || n > params_.chip_count) return Status::kInvalidArgument;
  if (params_.rate_hz != 10 && params_.rate_hz != 80) return Status::kInvalidArgument;
  if (config.rate_hz != params_.rate_hz || params_.max_clock_high_ns <= 0) {
    return Status::kInvalidArgument;
  }
  switch (config.gain) {
    case 128:
      input_ = Input::kA128;
      break;
    case 64:
      input_ = Input::kA64;
      break;
    case 32:
      input_ = Input::kB32;
      break;
    default:
      return Status::kInvalidArgument;
  }
  group_count_ = 0;
  for (std::size_t c = 0; c < n; ++c) {
    const Wiring& w = params_.wiring[c];
    if (w.clock == nullptr || w.data == nullptr) return Status::kInvalidArgument;
    std::size_t g = 0;
    while (g < group_count_ && groups_[g].clock != w.clock) ++g;
    if (g == group_count_) groups_[group_count_++] = Group{w.clock, 0, 0};
    groups_[g].chip_mask = static_cast<std::uint8_t>(groups_[g].chip_mask | Bit(c));
  }
  info_ = AdcInfo{};
  info_.channel_count = n;
  info_.min_counts = -(1 << 23);
  info_.max_counts = (1 << 23) - 1;
  info_.full_scale_nvv = FullScaleNvv(config.gain);
  info_.rate_hz = config.rate_hz;
  info_.simulated = false;
  counters_ = Hx711Counters{};
  longest_pulse_ns_ = 0;
  configured_ = true;

  // Reset every chip (known state: A128, fresh conversion), then read and drop conversions until
  // the selected input is active and settled. A chip that never answers makes the device absent.
  if (PowerDown() != Status::kOk || PowerUp() != Status::kOk) {
    configured_ = false;
    return Status::kUnavailable;
  }
  const std::uint32_t wait_us = 5u * 1000000u / params_.rate_hz;  // first conversion + margin
  for (int attempt = 0; attempt < 4 * (params_.discard_after_reset + 2); ++attempt) {
    bool settling = false;
    for (std::size_t g = 0; g < group_count_; ++g) settling |= groups_[g].discard_left > 0;
    if (!settling) break;
    if (DoWaitDataReady(wait_us) != Status::kOk) {
      configured_ = false;
      return Status::kUnavailable;
    }
    AdcSample scratch{};
    (void)DoRead(scratch);  // drops settling conversions; faults re-arm the discard count
    if (counters_.stuck_data > 0 || counters_.line_errors > 0) {
      configured_ = false;
      return Status::kUnavailable;
    }
  }
  for (std::size_t g = 0; g < group_count_; ++g) {
    if (groups_[g].discard_left > 0) {
      configured_ = false;
      return Status::kUnavailable;
    }
  }
  counters_ = Hx711Counters{};
  start_ns_ = clock_.NowNs();
  return Status::kOk;
}

Status Hx711Adc::DoWaitDataReady(std::uint32_t timeout_us) {
  if (!configured_) return Status::kNotConfigured;
  ready_ = false;
  const std::int64_t deadline_ns = clock_.NowNs() + std::int64_t{timeout_us} * 1000;
  std::uint8_t missing = 0;
  for (std::size_t c = 0; c < info_.channel_count; ++c) {
    bool low = false;
    if (gpio::WaitForLow(*params_.wiring[c].data, clock_, deadline_ns, low) != Status::kOk) {
      ++counters_.line_errors;
      return Status::kReadError;
    }
    if (!low) missing = static_cast<std::uint8_t>(missing | Bit(c));
  }
  if (missing != 0) {
    timeout_mask_ = missing;
    ++counters_.timeouts;
    return Status::kTimeout;
  }
  ready_ns_ = clock_.NowNs();
  ready_ = true;
  return Status::kOk;
}

Hx711Adc::ReadResult Hx711Adc::ReadGroup(std::size_t g, std::uint8_t& stuck_mask) {
  const Group& grp = groups_[g];
  const std::size_t n = info_.channel_count;
  for (std::size_t c = 0; c < n; ++c) {
    if ((grp.chip_mask & Bit(c)) != 0) raw_[c] = 0;
  }
  std::int64_t width_ns = 0;
  const int pulses = static_cast<int>(input_);
  for (int p = 0; p < pulses; ++p) {
    if (!Pulse(*grp.clock, width_ns)) return ReadResult::kLineError;
    if (width_ns > params_.max_clock_high_ns) return ReadResult::kLongPulse;
    if (p >= 24) continue;  // input-selection pulses carry no data
    for (std::size_t c = 0; c < n; ++c) {
      if ((grp.chip_mask & Bit(c)) == 0) continue;
      bool high = false;
      if (params_.wiring[c].data->Get(high) != Status::kOk) return ReadResult::kLineError;
      raw_[c] = (raw_[c] << 1) | (high ? 1u : 0u);
    }
  }
  // The 25th pulse pulls DOUT high until the next conversion: a low DOUT now is a stuck line.
  stuck_mask = 0;
  for (std::size_t c = 0; c < n; ++c) {
    if ((grp.chip_mask & Bit(c)) == 0) continue;
    bool high = false;
    if (params_.wiring[c].data->Get(high) != Status::kOk) return ReadResult::kLineError;
    if (!high) stuck_mask = static_cast<std::uint8_t>(stuck_mask | Bit(c));
  }
  return stuck_mask != 0 ? ReadResult::kStuck : ReadResult::kOk;
}

void Hx711Adc::Resynchronise(Group& grp) {
  // Power-cycle the group on purpose (clock high beyond the power-down time): a known state
  // (reset, A128), then drop the conversions of the settling time, the first of which selects
  // the configured input again.
  (void)grp.clock->Set(true);
  clock_.SleepNs(kPowerDownHoldNs);
  (void)grp.clock->Set(false);
  grp.discard_left = params_.discard_after_reset;
}

Status Hx711Adc::DoRead(AdcSample& out) {
  if (!configured_) return Status::kNotConfigured;
  if (!ready_) return Status::kTimeout;
  ready_ = false;
  out = AdcSample{};
  const std::uint8_t n = info_.channel_count;
  out.channel_count = n;
  out.timestamp_us = static_cast<std::uint64_t>(ready_ns_ - start_ns_) / 1000u;
  Status status = Status::kOk;
  for (std::size_t g = 0; g < group_count_; ++g) {
    Group& grp = groups_[g];
    std::uint8_t bad = 0;
    std::uint8_t stuck = 0;
    switch (ReadGroup(g, stuck)) {
      case ReadResult::kOk:
        if (grp.discard_left > 0) {
          --grp.discard_left;
          ++counters_.discarded;
          bad = grp.chip_mask;
        }
        break;
      case ReadResult::kLongPulse:
        // The chips on this clock powered down mid-read (or nearly): drop this sample and the
        // conversions of the settling time that follows.
        // Power-cycle them on purpose (a stretched pulse that stayed just under the chip's real
        // limit leaves them mid-read), which gives a known state: reset, A128.
        ++counters_.long_pulses;
        Resynchronise(grp);
        bad = grp.chip_mask;
        break;
      case ReadResult::kStuck:
        ++counters_.stuck_data;
        bad = stuck;
        break;
      case ReadResult::kLineError:
        // A GPIO call failed mid-read: the chips saw an unknown number of pulses, so the input
        // and gain of their next conversion are unknown too. Resynchronise as after a long pulse.
        ++counters_.line_errors;
        Resynchronise(grp);
        bad = grp.chip_mask;
        break;
    }
    for (std::size_t c = 0; c < n; ++c) {
      if ((grp.chip_mask & Bit(c)) == 0) continue;
      if ((bad & Bit(c)) != 0) {
        out.flags[c] |= kChannelReadError;
        status = Status::kReadError;
      } else {
        out.counts[c] = SignExtend24(raw_[c]);
      }
    }
  }
  return status;
}

}  // namespace ftstack::hal::hx711
