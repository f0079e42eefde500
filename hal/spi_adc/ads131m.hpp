// The ADS131M06/ADS131M08 backend: simultaneous-sampling 24-bit delta-sigma ADC over SPI + /DRDY.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/adc.hpp"
#include "hal/gpio/line.hpp"
#include "hal/spi/spi_device.hpp"

namespace ftstack::hal::spi_adc {

/// Register addresses, commands and bit fields of the ADS131M0x family (TI SBAS950, SBAS949).
namespace ads131m {
inline constexpr std::uint8_t kRegId = 0x00;
inline constexpr std::uint8_t kRegStatus = 0x01;
inline constexpr std::uint8_t kRegMode = 0x02;
inline constexpr std::uint8_t kRegClock = 0x03;
inline constexpr std::uint8_t kRegGain1 = 0x04;  ///< PGA gains of channels 0…3, 3 bits per nibble
inline constexpr std::uint8_t kRegGain2 = 0x05;  ///< channels 4…7
inline constexpr std::uint8_t kRegCount = 0x40;

inline constexpr std::uint16_t kCmdNull = 0x0000;
inline constexpr std::uint16_t kCmdReset = 0x0011;
inline constexpr std::uint16_t kCmdStandby = 0x0022;
inline constexpr std::uint16_t kCmdWakeup = 0x0033;
inline constexpr std::uint16_t kCmdLock = 0x0555;
inline constexpr std::uint16_t kCmdUnlock = 0x0655;
/// RREG 101a aaaa annn nnnn, WREG 011a aaaa annn nnnn (n = registers − 1).
[[nodiscard]] constexpr std::uint16_t Rreg(std::uint8_t addr, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(0xA000u | (addr & 0x3Fu) << 7 | ((count - 1u) & 0x7Fu));
}
[[nodiscard]] constexpr std::uint16_t Wreg(std::uint8_t addr, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(0x6000u | (addr & 0x3Fu) << 7 | ((count - 1u) & 0x7Fu));
}
/// WREG acknowledgement 010a aaaa ammm mmmm (m = registers written − 1).
[[nodiscard]] constexpr std::uint16_t WregAck(std::uint8_t addr, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(0x4000u | (addr & 0x3Fu) << 7 | ((count - 1u) & 0x7Fu));
}
/// RESET acknowledgement: FF20h + channel count (FF26h ADS131M06, FF28h ADS131M08).
[[nodiscard]] constexpr std::uint16_t ResetAck(std::uint8_t channels) {
  return static_cast<std::uint16_t>(0xFF20u | channels);
}

// MODE
inline constexpr std::uint16_t kModeRegCrcEn = 1u << 13;
inline constexpr std::uint16_t kModeRxCrcEn = 1u << 12;
inline constexpr std::uint16_t kModeCrcTypeAnsi = 1u << 11;
inline constexpr std::uint16_t kModeReset = 1u << 10;
inline constexpr std::uint16_t kModeWlength24 = 1u << 8;  ///< WLENGTH = 01b: 24-bit words
inline constexpr std::uint16_t kModeTimeout = 1u << 4;
// STATUS
inline constexpr std::uint16_t kStatusLock = 1u << 15;
inline constexpr std::uint16_t kStatusCrcErr = 1u << 12;
inline constexpr std::uint16_t kStatusReset = 1u << 10;
// CLOCK: CHn_EN bits 8+n, OSR bits 4:2, PWR bits 1:0 (10b high resolution)
inline constexpr std::uint16_t kClockPwrHighRes = 0x2;
/// Oversampling ratio of each OSR code; data rate = f_CLKIN / 2 / OSR.
inline constexpr std::array<std::uint32_t, 8> kOsr = {128, 256, 512, 1024, 2048, 4096, 8192, 16256};
/// PGA gains 1 … 128 are codes 0 … 7.
[[nodiscard]] constexpr int GainCode(std::uint16_t gain) {
  for (int c = 0; c < 8; ++c) {
    if (gain == (1u << c)) return c;
  }
  return -1;
}

/// CRC-16-CCITT as the chip computes it: polynomial 1021h, seed FFFFh, MSB first, no final XOR.
[[nodiscard]] constexpr std::uint16_t Crc16Ccitt(const std::uint8_t* data, std::size_t len) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < len; ++i) {
    crc = static_cast<std::uint16_t>(crc ^ (static_cast<std::uint16_t>(data[i]) << 8));
    for (int b = 0; b < 8; ++b) {
      crc = (crc & 0x8000u) != 0 ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021u)
                                 : static_cast<std::uint16_t>(crc << 1);
    }
  }
  return crc;
}
}  // namespace ads131m

/// Which member of the family is fitted (sets the channel count and the frame length).
enum class Ads131mModel : std::uint8_t { kAds131m06 = 6, kAds131m08 = 8 };

/// Board-level parameters.
struct Ads131mParams {
  Ads131mModel model = Ads131mModel::kAds131m08;
  std::uint32_t clkin_hz = 8192000;      ///< CLKIN frequency, Hz (data rate = clkin/2/OSR)
  std::uint32_t reference_uv = 1200000;  ///< internal reference, µV (input range ±VREF/gain)
  /// Bridge excitation, µV. The chip is not ratiometric (internal reference): counts convert to
  /// mV/V only for this excitation, which the board must regulate.
  std::uint32_t excitation_uv = 5000000;
  /// Per-channel PGA gain (1 … 128, powers of two); 0 takes AdcConfig::gain. Channels are
  /// reported on the scale of the smallest gain in use (counts of higher-gain channels divided
  /// exactly by the gain ratio, rounded), so AdcInfo::full_scale_nvv holds for every channel.
  std::array<std::uint16_t, kMaxChannels> channel_gain{};
  bool input_crc = true;      ///< RX_CRC_EN: the chip checks our frames' CRC
  std::uint8_t attempts = 3;  ///< tries per register transaction before giving up
};

/// Fault counters (reset by Configure).
struct Ads131mCounters {
  std::uint32_t crc_errors = 0;        ///< output frames whose CRC did not match (data dropped)
  std::uint32_t input_crc_errors = 0;  ///< STATUS.CRC_ERR seen: the chip rejected one of our frames
  std::uint32_t timeouts = 0;          ///< no /DRDY within the timeout
  std::uint32_t unexpected_resets = 0;  ///< STATUS.RESET seen after Configure (registers reapplied)
  std::uint32_t stale_channels = 0;     ///< channels whose DRDY bit was clear in a data frame
  std::uint32_t retries = 0;            ///< register transactions repeated
};

/// Largest frame: response + 8 channels + CRC, 24-bit words; WREG frames are never longer.
inline constexpr std::size_t kAds131mMaxFrameBytes = std::size_t{8 + 2} * 3;

/// ADS131M06/08 as a hal::Adc. Uses 24-bit words, CCITT CRC, all channels enabled, high-resolution
/// power mode; /DRDY (active low) on a GPIO input with falling-edge events.
///
/// Statuses: Configure → kOk, kInvalidArgument (rate not a data rate of clkin within 1 %, gain
/// not a power of two ≤ 128, more channels than the model has), kUnavailable (no answer to
/// RESET/ID: absent or wrong chip; see error()), kReadError (a register did not read back as
/// written after `attempts` tries). WaitDataReady → kOk, kTimeout, kNotConfigured, kReadError.
/// Read → kOk; kReadError with kChannelReadError on every channel for a frame CRC error, or with
/// kChannelTimeout on channels without new data; kTimeout without a preceding WaitDataReady.
class Ads131mAdc final : public Adc {
 public:
  Ads131mAdc(const Ads131mParams& params, spi::SpiDevice& spi, gpio::InputLine& drdy,
             gpio::Clock& clock);

  [[nodiscard]] const Ads131mCounters& counters() const { return counters_; }
  /// One-line reason of the last Configure failure ("" after success).
  [[nodiscard]] const char* error() const { return error_.data(); }
  /// Register values written by the last Configure (for diagnosis and tests).
  [[nodiscard]] std::uint16_t mode_register() const { return mode_; }
  [[nodiscard]] std::uint16_t clock_register() const { return clock_reg_; }
  [[nodiscard]] std::uint16_t gain_register(int index) const { return gain_reg_[index & 1]; }

 private:
  Status DoConfigure(const AdcConfig& config) override;
  Status DoWaitDataReady(std::uint32_t timeout_us) override;
  Status DoRead(AdcSample& out) override;
  AdcInfo DoInfo() const override { return info_; }

  enum class FrameResult : std::uint8_t { kOk, kCrcError, kBusError };
  /// One frame: command word, optional data words, input CRC word; validates the output CRC.
  FrameResult Frame(std::uint16_t command, const std::uint16_t* data, std::size_t n);
  [[nodiscard]] std::uint16_t Word16(std::size_t word) const;
  /// Command in one frame, its response (first word) from the next, a NULL frame.
  FrameResult Command(std::uint16_t command, const std::uint16_t* data, std::size_t n,
                      std::uint16_t& response);
  Status WriteVerified(std::uint8_t addr, std::uint16_t value);
  Status ApplyRegisters();
  Status Fail(Status s, const char* fmt, unsigned a = 0, unsigned b = 0, unsigned c = 0);

  Ads131mParams params_;
  spi::SpiDevice& spi_;
  gpio::InputLine& drdy_;
  gpio::Clock& clock_;
  AdcInfo info_{};
  std::uint8_t chip_channels_ = 8;
  std::size_t frame_bytes_ = 0;
  std::uint16_t mode_ = 0;
  std::uint16_t clock_reg_ = 0;
  std::array<std::uint16_t, 2> gain_reg_{};
  std::array<std::uint8_t, kMaxChannels> shift_{};  // log2(gain / smallest gain) per channel
  bool configured_ = false;
  bool ready_ = false;
  bool reapply_ = false;
  std::int64_t start_ns_ = 0;
  std::int64_t ready_ns_ = 0;
  std::array<std::uint8_t, kAds131mMaxFrameBytes> tx_{};
  std::array<std::uint8_t, kAds131mMaxFrameBytes> rx_{};
  Ads131mCounters counters_{};
  std::array<char, gpio::kErrorTextSize> error_{};
};

}  // namespace ftstack::hal::spi_adc
