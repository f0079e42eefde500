// Test fakes: virtual time, a PD_SCK line, and HX711 chips playing their side of the protocol.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include "hal/gpio/line.hpp"
#include "hal/hx711/hx711.hpp"

namespace ftstack::test {

/// Virtual monotonic time shared by all fakes of a test. Every GPIO call costs some time.
class FakeTime final : public hal::gpio::Clock {
 public:
  [[nodiscard]] std::int64_t NowNs() override { return now_ns; }
  void SleepNs(std::int64_t ns) override {
    if (ns > 0) now_ns += ns;
  }
  std::int64_t now_ns = 1000000;
};

/// One conversion a fake chip will produce: its 24-bit result and how much later than the regular
/// conversion period it completes (late data-ready).
struct Conversion {
  std::int32_t value = 0;  ///< signed result, -2^23 … 2^23-1
  std::int64_t extra_delay_ns = 0;
};

class FakeHx711;

/// A PD_SCK line. Each Set costs set_cost_ns; StallOnRise models the host being preempted right
/// after a rising edge, which stretches that clock-high pulse.
class FakeClockLine final : public hal::gpio::OutputLine {
 public:
  explicit FakeClockLine(FakeTime& time, std::int64_t set_cost_ns = 1000)
      : time_(time), set_cost_ns_(set_cost_ns) {}
  void Attach(FakeHx711* chip) { chips_.push_back(chip); }
  /// On the n-th rising edge from now (n ≥ 1), virtual time moves on by stall_ns before Set
  /// returns: the line stays high that much longer, as when the host is preempted mid-pulse.
  void StallOnRise(int n, std::int64_t stall_ns) {
    stall_at_rise_ = rises_ + n;
    stall_ns_ = stall_ns;
  }
  [[nodiscard]] int rises() const { return rises_; }
  [[nodiscard]] bool high() const { return high_; }

 private:
  hal::Status DoSet(bool high) override;
  FakeTime& time_;
  std::int64_t set_cost_ns_;
  std::vector<FakeHx711*> chips_;
  bool high_ = false;
  int rises_ = 0;
  int stall_at_rise_ = -1;
  std::int64_t stall_ns_ = 0;
};

/// One HX711 as seen from its pins: it converts on its own at rate_hz from a script, pulls DOUT
/// low when a result is ready, shifts the result out MSB first on PD_SCK rising edges, takes the
/// 25th…27th pulse as the input selection of the next conversion, powers down when PD_SCK stays
/// high for more than 60 µs and resets (A128) when it returns low. Implements its DOUT line.
class FakeHx711 final : public hal::gpio::InputLine {
 public:
  struct Record {  ///< one completed conversion
    std::int32_t value = 0;
    hal::hx711::Input input = hal::hx711::Input::kA128;  ///< input/gain it was converted with
    bool shifted_out = false;                            ///< all 24 bits were clocked out
  };

  FakeHx711(FakeTime& time, FakeClockLine& clock, std::uint32_t rate_hz,
            std::int64_t get_cost_ns = 500);

  void Push(const Conversion& c) {
    script_.push_back(c);
    Reschedule();
  }
  void Push(std::int32_t value, int times = 1) {
    for (int i = 0; i < times; ++i) Push(Conversion{value, 0});
  }
  void SetStuckHigh(bool on) { stuck_high_ = on; }
  void SetStuckLow(bool on) { stuck_low_ = on; }
  /// The `n`-th DOUT read from now fails (a GPIO error), once.
  void FailGetAfter(int n) {
    gets_ = 0;
    fail_gets_at_ = n;
  }

  [[nodiscard]] const std::vector<Record>& log() const { return log_; }
  [[nodiscard]] int power_downs() const { return power_downs_; }
  [[nodiscard]] int resets() const { return resets_; }
  /// Pulses while no result was ready, reads with a pulse count outside 25…27, results lost.
  [[nodiscard]] int violations() const { return violations_; }
  [[nodiscard]] bool powered() const { return powered_; }
  [[nodiscard]] std::size_t script_left() const { return script_.size(); }

  /// Called by the clock line after each level change, at the current virtual time.
  void OnClock(bool high);

 private:
  hal::Status DoGet(bool& high) override;
  hal::Status DoWaitForEdge(std::uint32_t timeout_us, bool& rising) override;
  hal::Status DoDiscardEdges() override;

  void Update();                      // advance the chip to time_.now_ns
  void Reschedule();                  // schedule the next conversion if none is pending
  void Complete(std::int64_t at_ns);  // a conversion finishes
  void EndRead();                     // input selection of a finished read takes effect
  [[nodiscard]] bool Level() const;
  void NoteLevel();

  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  FakeTime& time_;
  std::int64_t get_cost_ns_;
  std::int64_t period_ns_;
  std::deque<Conversion> script_;
  std::vector<Record> log_;
  std::deque<bool> edges_;  // queued DOUT edges, true = rising
  bool last_level_ = true;
  bool stuck_high_ = false;
  bool stuck_low_ = false;
  int gets_ = 0;
  int fail_gets_at_ = -1;
  bool powered_ = true;
  bool clock_high_ = false;
  std::int64_t rise_ns_ = 0;
  std::int64_t last_done_ns_ = 0;
  std::int64_t next_done_ns_ = kNever;
  bool has_data_ = false;  // a result is latched and not fully clocked out
  bool in_read_ = false;
  bool stray_ = false;  // the clock rose while no result was ready
  int read_pulses_ = 0;
  std::uint32_t shift_ = 0;
  std::size_t current_ = 0;  // log index of the latched result
  hal::hx711::Input selected_ = hal::hx711::Input::kA128;
  int power_downs_ = 0;
  int resets_ = 0;
  int violations_ = 0;
};

}  // namespace ftstack::test
