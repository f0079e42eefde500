// The GPIO line interface the bit-banged and data-ready drivers use: output/input lines, edges,
// time.
#pragma once

#include <cstdint>

#include "hal/adc.hpp"

namespace ftstack::hal::gpio {

/// Which transitions of an input line a wait reports.
enum class Edge : std::uint8_t {
  kNone = 0,  ///< the line is read by level only (no edge events requested)
  kRising,    ///< low → high
  kFalling,   ///< high → low
  kBoth,
};

/// A line driven by us (e.g. the HX711's PD_SCK). Levels are physical (true = high).
class OutputLine {
 public:
  virtual ~OutputLine() = default;
  OutputLine() = default;
  OutputLine(const OutputLine&) = delete;
  OutputLine& operator=(const OutputLine&) = delete;

  /// Drives the line. kOk, or kReadError when the kernel rejects the request.
  [[nodiscard]] Status Set(bool high) { return DoSet(high); }

 private:
  virtual Status DoSet(bool high) = 0;
};

/// A line we read (e.g. the HX711's DOUT, an ADC's /DRDY). Levels are physical (true = high).
///
/// Edge events are queued from the moment the line was requested with edges ≠ kNone. To wait for a
/// level without a race: DiscardEdges(), then Get(); if the level is not there yet, WaitForEdge().
class InputLine {
 public:
  virtual ~InputLine() = default;
  InputLine() = default;
  InputLine(const InputLine&) = delete;
  InputLine& operator=(const InputLine&) = delete;

  /// Reads the level into `high`. kOk or kReadError.
  [[nodiscard]] Status Get(bool& high) { return DoGet(high); }

  /// Waits up to timeout_us for the next queued or new edge of the requested kind; `rising` says
  /// which one it was. kOk, kTimeout, kNotConfigured (line requested without edges), kReadError.
  [[nodiscard]] Status WaitForEdge(std::uint32_t timeout_us, bool& rising) {
    return DoWaitForEdge(timeout_us, rising);
  }

  /// Drops the queued edge events (events older than this call are never reported).
  [[nodiscard]] Status DiscardEdges() { return DoDiscardEdges(); }

 private:
  virtual Status DoGet(bool& high) = 0;
  virtual Status DoWaitForEdge(std::uint32_t timeout_us, bool& rising) = 0;
  virtual Status DoDiscardEdges() = 0;
};

/// Monotonic time for pulse-width measurement and sample time stamps, ns.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Nanoseconds since an arbitrary fixed origin; never decreases.
  [[nodiscard]] virtual std::int64_t NowNs() = 0;
  /// Sleeps at least ns nanoseconds (used for power-down holds, never inside a clock pulse).
  virtual void SleepNs(std::int64_t ns) = 0;
};

/// Waits until `line` reads low or the clock passes deadline_ns: drops queued edges, checks the
/// level, then sleeps on falling edges (or polls every 100 µs on a line without edge events).
/// `low` says which happened. kOk, or kReadError when a GPIO call failed.
[[nodiscard]] inline Status WaitForLow(InputLine& line, Clock& clock, std::int64_t deadline_ns,
                                       bool& low) {
  if (line.DiscardEdges() != Status::kOk) return Status::kReadError;
  bool high = true;
  if (line.Get(high) != Status::kOk) return Status::kReadError;
  while (high) {
    const std::int64_t left_ns = deadline_ns - clock.NowNs();
    if (left_ns <= 0) {
      low = false;
      return Status::kOk;
    }
    bool rising = false;
    const auto left_us = static_cast<std::uint32_t>((left_ns + 999) / 1000);
    const Status s = line.WaitForEdge(left_us, rising);
    if (s == Status::kNotConfigured) {
      clock.SleepNs(left_ns < 100000 ? left_ns : 100000);
    } else if (s != Status::kOk && s != Status::kTimeout) {
      return Status::kReadError;
    }
    if (line.Get(high) != Status::kOk) return Status::kReadError;
  }
  low = true;
  return Status::kOk;
}

/// Capacity of an error message buffer of a GPIO/SPI backend (one line, NUL-terminated).
inline constexpr std::uint32_t kErrorTextSize = 160;

/// Where lines come from: one GPIO controller (a Linux gpiochip). Backends own the line objects in
/// fixed storage; the pointers stay valid for the chip's lifetime.
class Chip {
 public:
  virtual ~Chip() = default;
  Chip() = default;
  Chip(const Chip&) = delete;
  Chip& operator=(const Chip&) = delete;

  /// Requests line `offset` as an output at the initial level. kOk (and *line set),
  /// kUnavailable (chip not open, line busy or absent; see error()), kInvalidArgument (no free
  /// slot).
  [[nodiscard]] Status RequestOutput(std::uint32_t offset, bool initial_high, OutputLine** line) {
    return DoRequestOutput(offset, initial_high, line);
  }
  /// Requests line `offset` as an input reporting `edges`. Statuses as RequestOutput.
  [[nodiscard]] Status RequestInput(std::uint32_t offset, Edge edges, InputLine** line) {
    return DoRequestInput(offset, edges, line);
  }
  /// One-line description of the last failure ("" when none).
  [[nodiscard]] const char* error() const { return DoError(); }

 private:
  virtual Status DoRequestOutput(std::uint32_t offset, bool initial_high, OutputLine** line) = 0;
  virtual Status DoRequestInput(std::uint32_t offset, Edge edges, InputLine** line) = 0;
  virtual const char* DoError() const = 0;
};

}  // namespace ftstack::hal::gpio
