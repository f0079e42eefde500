// The libgpiod v1 (1.6.x C API) backend of the GPIO line interface: one Linux gpiochip.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/gpio/line.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace ftstack::hal::gpio {

/// Most lines one GpiodV1Chip hands out (a clock and a data line per bridge, plus two spare).
inline constexpr std::size_t kGpiodV1MaxLines = 2 * kMaxChannels + 2;

class GpiodV1Chip;

/// An output line requested through libgpiod v1.
class GpiodV1OutputLine final : public OutputLine {
 private:
  friend class GpiodV1Chip;
  Status DoSet(bool high) override;
  gpiod_line* line_ = nullptr;
};

/// An input line requested through libgpiod v1, optionally with edge events.
class GpiodV1InputLine final : public InputLine {
 private:
  friend class GpiodV1Chip;
  Status DoGet(bool& high) override;
  Status DoWaitForEdge(std::uint32_t timeout_us, bool& rising) override;
  Status DoDiscardEdges() override;
  gpiod_line* line_ = nullptr;
  Edge edges_ = Edge::kNone;
};

/// A gpiochip opened with libgpiod v1. Lines are released and the chip closed on destruction.
/// All failures return kUnavailable with a one-line reason in error() (no chip, no permission,
/// line busy); there is no heap use after Open.
class GpiodV1Chip final : public Chip {
 public:
  GpiodV1Chip() = default;
  ~GpiodV1Chip() override;

  /// Opens `path` (/dev/gpiochipN, or a chip name/number as gpiod_chip_open_lookup accepts).
  /// `consumer` labels the requested lines (shown by gpioinfo); it must outlive the chip.
  [[nodiscard]] Status Open(const char* path, const char* consumer = "ftstack");
  [[nodiscard]] bool is_open() const { return chip_ != nullptr; }

 private:
  Status DoRequestOutput(std::uint32_t offset, bool initial_high, OutputLine** line) override;
  Status DoRequestInput(std::uint32_t offset, Edge edges, InputLine** line) override;
  const char* DoError() const override { return error_.data(); }
  Status Fail(const char* what, std::uint32_t offset, int err);
  Status GetLine(std::uint32_t offset, std::size_t used, std::size_t capacity, gpiod_line** line);

  gpiod_chip* chip_ = nullptr;
  const char* consumer_ = "ftstack";
  std::array<char, 64> path_{};
  std::array<GpiodV1OutputLine, kGpiodV1MaxLines> outputs_{};
  std::array<GpiodV1InputLine, kGpiodV1MaxLines> inputs_{};
  std::size_t output_count_ = 0;
  std::size_t input_count_ = 0;
  std::array<char, kErrorTextSize> error_{};
};

}  // namespace ftstack::hal::gpio
