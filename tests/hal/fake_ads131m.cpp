#include "tests/hal/fake_ads131m.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "hal/spi_adc/ads131m.hpp"

namespace ftstack::test {

using hal::spi_adc::ads131m::Crc16Ccitt;
using hal::spi_adc::ads131m::kOsr;

namespace {
constexpr std::uint16_t kModeRxCrcEn = 1u << 12;
constexpr std::uint8_t kClock = 0x03;

std::uint16_t Word16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] << 8 | p[1]); }
void Put16(std::vector<std::uint8_t>& out, std::size_t at, std::uint16_t v) {
  out[at] = static_cast<std::uint8_t>(v >> 8);
  out[at + 1] = static_cast<std::uint8_t>(v);
}
}  // namespace

FakeAds131m::FakeAds131m(FakeTime& time, std::uint8_t channels) : time_(time), channels_(channels) {
  Reset();
}

std::int32_t FakeAds131m::Code(double uv, int gain) {
  const double code = std::nearbyint(uv * 1e-6 * gain / 1.2 * 8388608.0);
  return static_cast<std::int32_t>(std::clamp(code, -8388608.0, 8388607.0));
}

std::int64_t FakeAds131m::period_ns() const {
  const std::uint32_t osr = kOsr[(regs_[kClock] >> 2) & 7u];
  return static_cast<std::int64_t>(2ull * osr * 1000000000ull / 8192000ull);
}

std::size_t FakeAds131m::WordBytes() const {
  const unsigned wlength = (regs_[2] >> 8) & 3u;
  return wlength == 0 ? 2 : wlength == 1 ? 3 : 4;
}

std::uint16_t FakeAds131m::Status() const {
  return static_cast<std::uint16_t>((locked_ ? 0x8000u : 0u) | (crc_err_ ? 0x1000u : 0u) |
                                    (regs_[2] & 0x0F00u) | drdy_bits_);
}

void FakeAds131m::Reset() {
  regs_.fill(0);
  regs_[0] = static_cast<std::uint16_t>((0x20u | channels_) << 8);
  regs_[2] = 0x0510;
  regs_[kClock] = static_cast<std::uint16_t>(((1u << channels_) - 1u) << 8 | 0x0Eu);
  regs_[6] = 0x0600;
  for (unsigned n = 0; n < channels_; ++n) regs_[0x0C + 5 * n] = 0x8000;
  locked_ = false;
  standby_ = false;
  crc_err_ = false;
  unread_ = false;
  drdy_bits_ = 0;
  last_conv_ns_ = time_.now_ns;
  next_conv_ns_ = kNever;
  Schedule();
  NotePin();
}

void FakeAds131m::PowerGlitch() {
  Reset();
  response_ = Response::kStatus;
}

void FakeAds131m::Schedule() {
  if (next_conv_ns_ != kNever || standby_ || script_.empty()) return;
  next_conv_ns_ = std::max(last_conv_ns_ + period_ns(), time_.now_ns);
}

bool FakeAds131m::PinLevel() const { return drdy_stuck_high_ || !unread_; }

void FakeAds131m::NotePin() {
  const bool level = PinLevel();
  if (level != last_pin_) edges_.push_back(level);
  last_pin_ = level;
}

void FakeAds131m::Convert() {
  const InputsUv in = script_.front();
  script_.pop_front();
  for (unsigned i = 0; i < channels_; ++i) {
    const unsigned code = (regs_[4 + i / 4] >> (4 * (i % 4))) & 7u;
    data_[i] = Code(in[i], 1 << code);
  }
  // An unread result is replaced: /DRDY pulses high and falls again.
  if (unread_ && !drdy_stuck_high_) {
    edges_.push_back(true);
    edges_.push_back(false);
  }
  unread_ = true;
  drdy_bits_ = static_cast<std::uint8_t>((regs_[kClock] >> 8) & ((1u << channels_) - 1u));
  ++conversions_;
  last_conv_ns_ = next_conv_ns_;
  next_conv_ns_ = script_.empty() ? kNever : last_conv_ns_ + period_ns();
}

void FakeAds131m::Update() {
  while (next_conv_ns_ <= time_.now_ns) Convert();
  NotePin();
}

hal::Status FakeAds131m::DoTransfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) {
  time_.now_ns += 20000;  // ~30 bytes at 12 MHz plus driver overhead
  Update();
  ++frames_;
  const std::size_t wb = WordBytes();
  const std::size_t words = channels_ + 2u;
  std::vector<std::uint8_t> out(std::max(len, words * wb + 64), 0);
  std::size_t crc_at = 0;
  switch (response_) {
    case Response::kStatus:
      Put16(out, 0, Status());
      crc_err_ = false;  // cleared when STATUS is output
      break;
    case Response::kWord:
      Put16(out, 0, response_word_);
      break;
    case Response::kRegisters:
      Put16(out, 0, static_cast<std::uint16_t>(0xE000u | rreg_addr_ << 7 | (rreg_count_ - 1u)));
      break;
  }
  if (response_ == Response::kRegisters) {
    for (unsigned k = 0; k < rreg_count_; ++k) {
      Put16(out, (1 + k) * wb, regs_[(rreg_addr_ + k) & 0x3Fu]);
    }
    crc_at = (1u + rreg_count_) * wb;
  } else {
    const unsigned wlength = (regs_[2] >> 8) & 3u;
    for (unsigned i = 0; i < channels_; ++i) {
      const auto code = static_cast<std::uint32_t>(data_[i]) & 0xFFFFFFu;
      std::uint32_t word = code;  // 24 bit
      if (wlength == 0) word = code >> 8;
      if (wlength == 2) word = code << 8;
      if (wlength == 3) word = static_cast<std::uint32_t>(data_[i]);
      for (std::size_t b = 0; b < wb; ++b) {
        out[(1 + i) * wb + b] = static_cast<std::uint8_t>(word >> (8 * (wb - 1 - b)));
      }
    }
    crc_at = (1u + channels_) * wb;
    unread_ = false;
    drdy_bits_ = 0;
  }
  Put16(out, crc_at, Crc16Ccitt(out.data(), crc_at));
  if (corrupt_out_ > 0) {
    out[wb + 1] ^= 0x10;  // a bit of channel 0's result
    --corrupt_out_;
  }
  std::copy(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(len), rx);
  NotePin();

  std::vector<std::uint8_t> in(tx, tx + len);
  in.resize(std::max(len, 16 * wb), 0);
  Execute(in.data(), wb);
  NotePin();
  return hal::Status::kOk;
}

void FakeAds131m::Execute(const std::uint8_t* in_const, std::size_t wb) {
  std::vector<std::uint8_t> in(in_const, in_const + 16 * wb);
  const std::uint16_t cmd = Word16(in.data());
  const bool is_wreg = (cmd & 0xE000u) == 0x6000u;
  const bool is_rreg = (cmd & 0xE000u) == 0xA000u;
  const std::uint8_t addr = static_cast<std::uint8_t>((cmd >> 7) & 0x3Fu);
  const unsigned count = (cmd & 0x7Fu) + 1u;
  const std::size_t data_words = is_wreg ? count : 0;
  if (is_wreg && corrupt_wreg_ > 0) {
    in[wb + 1] ^= 0x01;  // a bit of the first register value, after the host computed its CRC
    --corrupt_wreg_;
  }
  bool crc_ok = true;
  if ((regs_[2] & kModeRxCrcEn) != 0 && (1 + data_words) * wb + 2 <= in.size()) {
    const std::size_t at = (1 + data_words) * wb;
    crc_ok = Crc16Ccitt(in.data(), at) == Word16(&in[at]);
  }
  response_ = Response::kStatus;
  if (!crc_ok) {
    crc_err_ = true;
    ++input_crc_errors_;
    if (!is_wreg) return;  // not executed; WREG is executed anyway (data sheet)
  }
  if (locked_ && cmd != 0x0000 && cmd != 0x0655 && !is_rreg) return;
  auto echo = [this, cmd] {
    response_ = Response::kWord;
    response_word_ = cmd;
  };
  if (cmd == 0x0000) {
    response_ = Response::kStatus;
  } else if (cmd == 0x0011) {
    Reset();
    response_ = Response::kWord;
    response_word_ = static_cast<std::uint16_t>(0xFF20u | channels_);
  } else if (cmd == 0x0022) {
    standby_ = true;
    next_conv_ns_ = kNever;
    echo();
  } else if (cmd == 0x0033) {
    standby_ = false;
    Schedule();
    echo();
  } else if (cmd == 0x0555) {
    locked_ = true;
    echo();
  } else if (cmd == 0x0655) {
    locked_ = false;
    echo();
  } else if (is_rreg) {
    if (count == 1) {
      response_ = Response::kWord;
      response_word_ = addr == 1 ? Status() : regs_[addr];
    } else {
      response_ = Response::kRegisters;
      rreg_addr_ = addr;
      rreg_count_ = static_cast<std::uint8_t>(count);
    }
  } else if (is_wreg) {
    for (unsigned k = 0; k < count; ++k) {
      const unsigned a = addr + k;
      if (a < 2 || a >= regs_.size()) continue;  // ID and STATUS are read-only
      regs_[a] = Word16(&in[(1 + k) * wb]);
      if (a == kClock) {  // new OSR: conversions restart
        last_conv_ns_ = time_.now_ns;
        next_conv_ns_ = kNever;
        Schedule();
      }
    }
    if (crc_ok) {
      response_ = Response::kWord;
      response_word_ = static_cast<std::uint16_t>(0x4000u | addr << 7 | (count - 1u));
    }
  }
}

hal::Status FakeAds131m::Drdy::DoGet(bool& high) {
  chip_.time_.now_ns += 500;
  chip_.Update();
  high = chip_.PinLevel();
  return hal::Status::kOk;
}

hal::Status FakeAds131m::Drdy::DoWaitForEdge(std::uint32_t timeout_us, bool& rising) {
  chip_.Update();
  const std::int64_t deadline = chip_.time_.now_ns + std::int64_t{timeout_us} * 1000;
  while (chip_.edges_.empty()) {
    const std::int64_t next = chip_.drdy_stuck_high_ ? kNever : chip_.next_conv_ns_;
    chip_.time_.now_ns = std::max(chip_.time_.now_ns, std::min(next, deadline));
    chip_.Update();
    if (next > deadline) break;
  }
  if (chip_.edges_.empty()) return hal::Status::kTimeout;
  rising = chip_.edges_.front();
  chip_.edges_.pop_front();
  return hal::Status::kOk;
}

hal::Status FakeAds131m::Drdy::DoDiscardEdges() {
  chip_.Update();
  chip_.edges_.clear();
  return hal::Status::kOk;
}

}  // namespace ftstack::test
