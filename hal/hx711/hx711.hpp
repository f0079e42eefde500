// The HX711 backend: one HX711 per bridge, bit-banged over GPIO lines, with pulse-width fault
// checks.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/adc.hpp"
#include "hal/gpio/line.hpp"

namespace ftstack::hal::hx711 {

/// Input and gain of the next conversion, selected by the number of PD_SCK pulses of a read.
enum class Input : std::uint8_t {
  kA128 = 25,  ///< channel A, gain 128 (the power-on default)
  kB32 = 26,   ///< channel B, gain 32
  kA64 = 27,   ///< channel A, gain 64
};

/// The HX711 powers down when PD_SCK stays high longer than 60 µs (datasheet), which corrupts the
/// read in progress and resets the chip to channel A, gain 128.
inline constexpr std::int64_t kPowerDownPulseNs = 60000;

/// The gain of `input` (128, 32 or 64).
[[nodiscard]] constexpr std::uint16_t GainOf(Input input) {
  return input == Input::kA128 ? 128 : input == Input::kB32 ? 32 : 64;
}

/// Bridge input at the positive rail for an HX711 gain, nV/V: the differential input range is
/// ±0.5·AVDD/gain and the bridge is excited from AVDD (ratiometric), so 0.5e9 / gain.
[[nodiscard]] constexpr std::int64_t FullScaleNvv(std::uint16_t gain) {
  return gain == 0 ? 0 : 500000000LL / gain;
}

/// Decodes a 24-bit two's-complement word (bits 23…0) into a signed count.
[[nodiscard]] constexpr std::int32_t SignExtend24(std::uint32_t word) {
  word &= 0xFFFFFFu;
  return (word & 0x800000u) != 0 ? static_cast<std::int32_t>(word) - 0x1000000
                                 : static_cast<std::int32_t>(word);
}

/// The wiring of one HX711: its PD_SCK (output) and DOUT (input, falling-edge events) lines.
/// Bridges may share one clock line (then they are clocked together and share gain and resets).
struct Wiring {
  gpio::OutputLine* clock = nullptr;
  gpio::InputLine* data = nullptr;
};

/// Board-level parameters of the HX711 front end.
struct Hx711Params {
  std::uint8_t chip_count = 0;                ///< wired HX711s, one per bridge (≤ kMaxChannels)
  std::array<Wiring, kMaxChannels> wiring{};  ///< [0, chip_count)
  std::uint32_t rate_hz = 10;                 ///< RATE pin strap: 10 or 80 samples/s
  /// Longest accepted clock-high pulse, ns: the measured bound of every pulse (time from before
  /// the rising edge to after the falling edge) must stay at or below it.
  std::int64_t max_clock_high_ns = kPowerDownPulseNs;
  /// Conversions discarded after a chip reset (configure, power-up, over-long pulse): the first one
  /// is at the default A128 input; the datasheet's settling time is 4 conversion periods.
  std::uint8_t discard_after_reset = 4;
};

/// Fault counters, for diagnosis (never reset except by Configure).
struct Hx711Counters {
  std::uint32_t long_pulses = 0;  ///< reads aborted by a clock-high pulse over the limit
  std::uint32_t timeouts = 0;     ///< WaitDataReady calls that timed out
  std::uint32_t stuck_data = 0;   ///< DOUT still low after the gain pulses (line stuck low)
  std::uint32_t discarded = 0;    ///< conversions dropped while a chip settled after a reset
  std::uint32_t line_errors = 0;  ///< GPIO calls that failed
};

/// N HX711 converters read as one hal::Adc (channel i = chip i).
///
/// Statuses: Configure → kOk, kInvalidArgument (gain not 128/64/32, rate not the strapped one,
/// more channels than chips, missing lines), kUnavailable (a chip never signals data-ready or its
/// DOUT is stuck). WaitDataReady → kOk, kTimeout (last_timeout_mask() says which chips),
/// kNotConfigured, kReadError (GPIO failure). Read → kOk; kReadError with kChannelReadError on the
/// affected channels when a pulse was too long, DOUT stuck low, or a chip is still settling after a
/// reset; kTimeout when called without a successful WaitDataReady.
class Hx711Adc final : public Adc {
 public:
  Hx711Adc(const Hx711Params& params, gpio::Clock& clock);

  /// Powers every chip down (PD_SCK held high; the chips sleep after 60 µs).
  [[nodiscard]] Status PowerDown();
  /// Powers the chips up (PD_SCK low): they reset to A128 and restart converting. The next
  /// discard_after_reset conversions are dropped.
  [[nodiscard]] Status PowerUp();

  [[nodiscard]] const Hx711Counters& counters() const { return counters_; }
  /// Bit i set: chip i did not signal data-ready in the last WaitDataReady that timed out.
  [[nodiscard]] std::uint8_t last_timeout_mask() const { return timeout_mask_; }
  /// The longest clock-high pulse bound measured since Configure, ns.
  [[nodiscard]] std::int64_t longest_pulse_ns() const { return longest_pulse_ns_; }

 private:
  struct Group {  // chips sharing one clock line
    gpio::OutputLine* clock = nullptr;
    std::uint8_t chip_mask = 0;     // bit i: chip i
    std::uint8_t discard_left = 0;  // conversions still to drop after a reset
  };

  Status DoConfigure(const AdcConfig& config) override;
  Status DoWaitDataReady(std::uint32_t timeout_us) override;
  Status DoRead(AdcSample& out) override;
  AdcInfo DoInfo() const override { return info_; }

  enum class ReadResult : std::uint8_t { kOk, kLongPulse, kStuck, kLineError };
  /// Clocks out one group (24 data pulses + the input-selection pulses) into raw_.
  ReadResult ReadGroup(std::size_t g, std::uint8_t& stuck_mask);
  /// One PD_SCK pulse with its width bound measured; false when the GPIO call failed.
  bool Pulse(gpio::OutputLine& clock, std::int64_t& width_ns);
  void ResetGroups();
  /// After a read whose pulse count is unknown: power-cycle the group, re-arm the discard.
  void Resynchronise(Group& grp);

  Hx711Params params_;
  gpio::Clock& clock_;
  AdcInfo info_{};
  Input input_ = Input::kA128;
  bool configured_ = false;
  bool ready_ = false;
  std::array<Group, kMaxChannels> groups_{};
  std::size_t group_count_ = 0;
  std::array<std::uint32_t, kMaxChannels> raw_{};
  std::int64_t start_ns_ = 0;
  std::int64_t ready_ns_ = 0;
  std::int64_t longest_pulse_ns_ = 0;
  std::uint8_t timeout_mask_ = 0;
  Hx711Counters counters_{};
};

}  // namespace ftstack::hal::hx711
