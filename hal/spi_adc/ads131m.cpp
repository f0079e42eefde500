#include "hal/spi_adc/ads131m.hpp"

#include <cstdio>

namespace ftstack::hal::spi_adc {
namespace {

constexpr std::size_t kWordBytes = 3;  // WLENGTH 24 bit

[[nodiscard]] constexpr std::int32_t SignExtend24(std::uint32_t word) {
  return (word & 0x800000u) != 0 ? static_cast<std::int32_t>(word) - 0x1000000
                                 : static_cast<std::int32_t>(word);
}

/// x / 2^shift rounded to nearest (ties away from zero), exact for shift 0.
[[nodiscard]] constexpr std::int32_t DivPow2Round(std::int32_t x, unsigned shift) {
  if (shift == 0) return x;
  const std::int32_t half = 1 << (shift - 1);
  return x >= 0 ? (x + half) >> shift : -((-x + half) >> shift);
}

}  // namespace

using namespace ads131m;

Ads131mAdc::Ads131mAdc(const Ads131mParams& params, spi::SpiDevice& spi, gpio::InputLine& drdy,
                       gpio::Clock& clock)
    : params_(params), spi_(spi), drdy_(drdy), clock_(clock) {}

Status Ads131mAdc::Fail(Status s, const char* fmt, unsigned a, unsigned b, unsigned c) {
  std::snprintf(error_.data(), error_.size(), fmt, a, b, c);
  return s;
}

std::uint16_t Ads131mAdc::Word16(std::size_t word) const {
  return static_cast<std::uint16_t>(rx_[word * kWordBytes] << 8 | rx_[word * kWordBytes + 1]);
}

Ads131mAdc::FrameResult Ads131mAdc::Frame(std::uint16_t command, const std::uint16_t* data,
                                          std::size_t n) {
  const std::size_t words = frame_bytes_ / kWordBytes;
  if (n + 2 > words) return FrameResult::kBusError;
  for (std::size_t i = 0; i < frame_bytes_; ++i) tx_[i] = 0;
  auto put = [this](std::size_t word, std::uint16_t v) {
    tx_[word * kWordBytes] = static_cast<std::uint8_t>(v >> 8);
    tx_[word * kWordBytes + 1] = static_cast<std::uint8_t>(v);
  };
  put(0, command);
  for (std::size_t i = 0; i < n; ++i) put(1 + i, data[i]);
  // Input CRC over the command and its data words, padding included; the chip checks it when
  // RX_CRC_EN is set and ignores it otherwise.
  put(1 + n, Crc16Ccitt(tx_.data(), (1 + n) * kWordBytes));
  if (spi_.Transfer(tx_.data(), rx_.data(), frame_bytes_) != Status::kOk) {
    return FrameResult::kBusError;
  }
  // Output CRC over every word before it (response + channel data).
  const std::uint16_t want = Crc16Ccitt(rx_.data(), (words - 1) * kWordBytes);
  if (Word16(words - 1) != want) {
    ++counters_.crc_errors;
    return FrameResult::kCrcError;
  }
  return FrameResult::kOk;
}

Ads131mAdc::FrameResult Ads131mAdc::Command(std::uint16_t command, const std::uint16_t* data,
                                            std::size_t n, std::uint16_t& response) {
  // The output of the command's own frame (previous response, data) does not matter here.
  if (Frame(command, data, n) == FrameResult::kBusError) return FrameResult::kBusError;
  const FrameResult r = Frame(kCmdNull, nullptr, 0);
  if (r == FrameResult::kOk) response = Word16(0);
  return r;
}

Status Ads131mAdc::WriteVerified(std::uint8_t addr, std::uint16_t value) {
  std::uint16_t readback = 0;
  for (int attempt = 0; attempt < params_.attempts; ++attempt) {
    if (attempt > 0) ++counters_.retries;
    std::uint16_t ack = 0;
    // A WREG is executed even when its input CRC fails (then acknowledged like NULL, with
    // STATUS): only the read-back says what the register holds.
    FrameResult r = Command(Wreg(addr), &value, 1, ack);
    if (r == FrameResult::kBusError) return Status::kReadError;
    if (r == FrameResult::kOk && ack != WregAck(addr) && (ack & kStatusCrcErr) != 0) {
      ++counters_.input_crc_errors;
    }
    r = Command(Rreg(addr), nullptr, 0, readback);
    if (r == FrameResult::kBusError) return Status::kReadError;
    if (r == FrameResult::kOk && readback == value) return Status::kOk;
  }
  return Fail(Status::kReadError, "ADS131M register %02Xh reads %04Xh after writing %04Xh", addr,
              readback, value);
}

Status Ads131mAdc::ApplyRegisters() {
  // UNLOCK first (a locked interface ignores RESET), then RESET: known state, 24-bit words.
  std::uint16_t response = 0;
  bool ok = false;
  for (int attempt = 0; attempt < params_.attempts && !ok; ++attempt) {
    std::uint16_t ignored = 0;
    if (Command(kCmdUnlock, nullptr, 0, ignored) == FrameResult::kBusError ||
        Command(kCmdReset, nullptr, 0, response) == FrameResult::kBusError) {
      return Fail(Status::kUnavailable, "ADS131M0%u: SPI transfer failed", chip_channels_);
    }
    ok = response == ResetAck(chip_channels_);
  }
  if (!ok) {
    return Fail(Status::kUnavailable,
                "no ADS131M0%u answers on the SPI bus (RESET response %04Xh, expected %04Xh)",
                chip_channels_, response, ResetAck(chip_channels_));
  }
  clock_.SleepNs(10000);  // t_REGACQ (5 µs) before the first register access
  std::uint16_t id = 0;
  ok = false;
  for (int attempt = 0; attempt < params_.attempts && !ok; ++attempt) {
    if (Command(Rreg(kRegId), nullptr, 0, id) == FrameResult::kBusError) {
      return Fail(Status::kUnavailable, "ADS131M0%u: SPI transfer failed", chip_channels_);
    }
    ok = ((id >> 8) & 0x0Fu) == chip_channels_;
  }
  if (!ok) {
    return Fail(Status::kUnavailable, "ID register %04Xh is not that of an ADS131M0%u", id,
                chip_channels_);
  }
  // MODE first: it clears the RESET flag and switches the input CRC check on.
  Status s = Status::kOk;
  if ((s = WriteVerified(kRegMode, mode_)) != Status::kOk) return s;
  if ((s = WriteVerified(kRegClock, clock_reg_)) != Status::kOk) return s;
  if ((s = WriteVerified(kRegGain1, gain_reg_[0])) != Status::kOk) return s;
  if (chip_channels_ > 4 && (s = WriteVerified(kRegGain2, gain_reg_[1])) != Status::kOk) return s;
  error_[0] = '\0';
  return Status::kOk;
}

Status Ads131mAdc::DoConfigure(const AdcConfig& config) {
  configured_ = false;
  ready_ = false;
  reapply_ = false;
  error_[0] = '\0';
  chip_channels_ = static_cast<std::uint8_t>(params_.model);
  const std::uint8_t n = config.channel_count;
  if (n > chip_channels_ || params_.clkin_hz == 0 || params_.reference_uv == 0 ||
      params_.excitation_uv == 0 || params_.attempts == 0) {
    return Status::kInvalidArgument;
  }
  // Data rate: the OSR whose rate is within 1 % of the request.
  int osr_code = -1;
  std::uint32_t rate_hz = 0;
  for (int c = 0; c < 8; ++c) {
    const std::uint64_t denom = 2ull * kOsr[static_cast<std::size_t>(c)];
    const std::uint64_t r = (params_.clkin_hz + denom / 2) / denom;
    const std::uint64_t diff = r > config.rate_hz ? r - config.rate_hz : config.rate_hz - r;
    if (diff * 100 <= r) {
      osr_code = c;
      rate_hz = static_cast<std::uint32_t>(r);
    }
  }
  if (osr_code < 0) return Status::kInvalidArgument;
  // Gains: per-channel override or the common one; unused channels take the common one.
  std::array<int, kMaxChannels> code{};
  int min_code = 8;
  for (std::size_t i = 0; i < chip_channels_; ++i) {
    const std::uint16_t g =
        i < n && params_.channel_gain[i] != 0 ? params_.channel_gain[i] : config.gain;
    code[i] = GainCode(g);
    if (code[i] < 0) return Status::kInvalidArgument;
    if (i < n && code[i] < min_code) min_code = code[i];
  }
  gain_reg_ = {};
  for (std::size_t i = 0; i < chip_channels_; ++i) {
    shift_[i] = static_cast<std::uint8_t>(i < n ? code[i] - min_code : 0);
    gain_reg_[i / 4] = static_cast<std::uint16_t>(gain_reg_[i / 4] | code[i] << (4 * (i % 4)));
  }
  mode_ = static_cast<std::uint16_t>(kModeWlength24 | kModeTimeout |
                                     (params_.input_crc ? kModeRxCrcEn : 0));
  clock_reg_ = static_cast<std::uint16_t>(((1u << chip_channels_) - 1u) << 8 | osr_code << 2 |
                                          kClockPwrHighRes);
  frame_bytes_ = (chip_channels_ + 2u) * kWordBytes;
  counters_ = Ads131mCounters{};

  const Status s = ApplyRegisters();
  if (s != Status::kOk) return s;

  info_ = AdcInfo{};
  info_.channel_count = n;
  info_.min_counts = -(1 << 23);
  info_.max_counts = (1 << 23) - 1;
  // ±VREF/gain at the smallest gain in use, as a fraction of the excitation, nV/V.
  info_.full_scale_nvv = static_cast<std::int64_t>(params_.reference_uv) * 1000000000LL /
                         (static_cast<std::int64_t>(1 << min_code) * params_.excitation_uv);
  info_.rate_hz = rate_hz;
  info_.simulated = false;
  configured_ = true;
  start_ns_ = clock_.NowNs();
  return Status::kOk;
}

Status Ads131mAdc::DoWaitDataReady(std::uint32_t timeout_us) {
  if (!configured_) return Status::kNotConfigured;
  ready_ = false;
  const std::int64_t deadline_ns = clock_.NowNs() + std::int64_t{timeout_us} * 1000;
  if (reapply_) {
    if (ApplyRegisters() != Status::kOk) return Status::kReadError;
    reapply_ = false;
  }
  bool low = false;
  if (gpio::WaitForLow(drdy_, clock_, deadline_ns, low) != Status::kOk) return Status::kReadError;
  if (!low) {
    ++counters_.timeouts;
    return Status::kTimeout;
  }
  ready_ns_ = clock_.NowNs();
  ready_ = true;
  return Status::kOk;
}

Status Ads131mAdc::DoRead(AdcSample& out) {
  if (!configured_) return Status::kNotConfigured;
  if (!ready_) return Status::kTimeout;
  ready_ = false;
  out = AdcSample{};
  const std::uint8_t n = info_.channel_count;
  out.channel_count = n;
  out.timestamp_us = static_cast<std::uint64_t>(ready_ns_ - start_ns_) / 1000u;
  auto flag_all = [&out, n](std::uint8_t flag) {
    for (std::size_t i = 0; i < n; ++i) out.flags[i] |= flag;
    return Status::kReadError;
  };
  if (Frame(kCmdNull, nullptr, 0) != FrameResult::kOk) return flag_all(kChannelReadError);
  const std::uint16_t status = Word16(0);
  if ((status & kStatusReset) != 0) {
    // The chip reset on its own (supply glitch): registers are back to defaults.
    ++counters_.unexpected_resets;
    reapply_ = true;
    return flag_all(kChannelReadError);
  }
  if ((status & kStatusCrcErr) != 0) ++counters_.input_crc_errors;
  Status result = Status::kOk;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t at = (1 + i) * kWordBytes;
    const std::uint32_t word = static_cast<std::uint32_t>(rx_[at]) << 16 |
                               static_cast<std::uint32_t>(rx_[at + 1]) << 8 | rx_[at + 2];
    out.counts[i] = DivPow2Round(SignExtend24(word), shift_[i]);
    if ((status & (1u << i)) == 0) {  // DRDYn clear: no new result on this channel
      out.flags[i] |= kChannelTimeout;
      ++counters_.stale_channels;
      result = Status::kReadError;
    }
  }
  return result;
}

}  // namespace ftstack::hal::spi_adc
