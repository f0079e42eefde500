// Test fake: an ADS131M06/08 behind the SPI transfer interface, with its /DRDY pin and fault hooks.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <limits>

#include "hal/gpio/line.hpp"
#include "hal/spi/spi_device.hpp"
#include "tests/hal/fake_hx711.hpp"

namespace ftstack::test {

/// Differential input voltage of every channel for one conversion, µV.
using InputsUv = std::array<double, 8>;

/// Models the chip from its data sheet: register map with reset values and read-only registers,
/// word length from MODE, command/response pipelining (the response comes in the next frame),
/// NULL/RESET/STANDBY/WAKEUP/LOCK/UNLOCK/RREG (single and multiple)/WREG, input CRC check when
/// RX_CRC_EN (commands with a bad CRC are not executed, except WREG), output CRC over the whole
/// frame, STATUS (LOCK, CRC_ERR cleared when output, RESET, WLENGTH, DRDYn), conversions every
/// 2·OSR/f_CLKIN with the PGA (code = round(v·gain/1.2 V·2^23), clipped), /DRDY low while a result
/// is unread. Conversions stop when the input script runs out.
class FakeAds131m final : public hal::spi::SpiDevice {
 public:
  FakeAds131m(FakeTime& time, std::uint8_t channels);

  [[nodiscard]] hal::gpio::InputLine& drdy() { return drdy_; }
  void PushInputs(const InputsUv& uv, int times = 1) {
    for (int i = 0; i < times; ++i) script_.push_back(uv);
    Schedule();
  }

  // Faults.
  void CorruptNextOutputFrames(int n) { corrupt_out_ = n; }  ///< flip a data bit on MISO
  void CorruptNextWregData(int n) { corrupt_wreg_ = n; }     ///< flip a data bit of WREG on MOSI
  void SetDrdyStuckHigh(bool on) { drdy_stuck_high_ = on; }  ///< /DRDY never goes low
  void PowerGlitch();                                        ///< reset as after a brown-out
  void Lock() { locked_ = true; }                            ///< as left locked by a previous run

  [[nodiscard]] std::uint16_t reg(std::uint8_t addr) const { return regs_[addr & 0x3F]; }
  [[nodiscard]] std::uint16_t Status() const;
  [[nodiscard]] int frames() const { return frames_; }
  [[nodiscard]] int input_crc_errors() const { return input_crc_errors_; }
  [[nodiscard]] int conversions() const { return conversions_; }
  [[nodiscard]] std::int64_t period_ns() const;
  /// The code the PGA and converter produce for `uv` at `gain` (the chip's transfer function).
  [[nodiscard]] static std::int32_t Code(double uv, int gain);

 private:
  class Drdy final : public hal::gpio::InputLine {
   public:
    explicit Drdy(FakeAds131m& chip) : chip_(chip) {}

   private:
    hal::Status DoGet(bool& high) override;
    hal::Status DoWaitForEdge(std::uint32_t timeout_us, bool& rising) override;
    hal::Status DoDiscardEdges() override;
    FakeAds131m& chip_;
  };

  hal::Status DoTransfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) override;
  void Reset();
  void Schedule();
  void Update();
  void Convert();
  void Execute(const std::uint8_t* in, std::size_t word_bytes);
  [[nodiscard]] bool PinLevel() const;
  void NotePin();
  [[nodiscard]] std::size_t WordBytes() const;

  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  FakeTime& time_;
  std::uint8_t channels_;
  Drdy drdy_{*this};
  std::array<std::uint16_t, 64> regs_{};
  std::deque<InputsUv> script_;
  std::array<std::int32_t, 8> data_{};
  std::uint8_t drdy_bits_ = 0;
  bool unread_ = false;
  bool crc_err_ = false;
  bool locked_ = false;
  bool standby_ = false;
  bool drdy_stuck_high_ = false;
  bool last_pin_ = true;
  std::deque<bool> edges_;
  std::int64_t next_conv_ns_ = kNever;
  std::int64_t last_conv_ns_ = 0;
  // Response of the previous command, output in the next frame.
  enum class Response : std::uint8_t { kStatus, kWord, kRegisters };
  Response response_ = Response::kStatus;
  std::uint16_t response_word_ = 0;
  std::uint8_t rreg_addr_ = 0;
  std::uint8_t rreg_count_ = 0;
  int corrupt_out_ = 0;
  int corrupt_wreg_ = 0;
  int frames_ = 0;
  int input_crc_errors_ = 0;
  int conversions_ = 0;
};

/// An SPI bus with nothing attached: MISO idles at `level` (0x00 or 0xFF).
class AbsentSpiDevice final : public hal::spi::SpiDevice {
 public:
  explicit AbsentSpiDevice(std::uint8_t level) : level_(level) {}

 private:
  hal::Status DoTransfer(const std::uint8_t*, std::uint8_t* rx, std::size_t len) override {
    for (std::size_t i = 0; i < len; ++i) rx[i] = level_;
    return hal::Status::kOk;
  }
  std::uint8_t level_;
};

}  // namespace ftstack::test
