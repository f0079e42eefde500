#include "tests/hal/fake_hx711.hpp"

#include <algorithm>

namespace ftstack::test {

using hal::Status;
using hal::hx711::Input;
using hal::hx711::kPowerDownPulseNs;

Status FakeClockLine::DoSet(bool high) {
  time_.now_ns += set_cost_ns_;
  if (high == high_) return Status::kOk;
  high_ = high;
  if (high) ++rises_;
  for (FakeHx711* chip : chips_) chip->OnClock(high);
  if (high && rises_ == stall_at_rise_) time_.now_ns += stall_ns_;
  return Status::kOk;
}

FakeHx711::FakeHx711(FakeTime& time, FakeClockLine& clock, std::uint32_t rate_hz,
                     std::int64_t get_cost_ns)
    : time_(time),
      get_cost_ns_(get_cost_ns),
      period_ns_(1000000000LL / rate_hz),
      last_done_ns_(time.now_ns) {
  clock.Attach(this);
}

void FakeHx711::Reschedule() {
  if (next_done_ns_ != kNever || !powered_ || script_.empty()) return;
  next_done_ns_ =
      std::max(last_done_ns_ + period_ns_, time_.now_ns) + script_.front().extra_delay_ns;
}

void FakeHx711::EndRead() {
  if (read_pulses_ >= 25 && read_pulses_ <= 27) {
    selected_ = static_cast<Input>(read_pulses_);
  } else {
    ++violations_;  // a read that stopped early or ran on: the chip's state is undefined
  }
  in_read_ = false;
  read_pulses_ = 0;
}

void FakeHx711::Complete(std::int64_t at_ns) {
  const Conversion c = script_.front();
  script_.pop_front();
  last_done_ns_ = at_ns;
  next_done_ns_ = script_.empty() ? kNever : at_ns + period_ns_ + script_.front().extra_delay_ns;
  // A read still in progress (stopped before the 25th pulse) is abandoned and counted by EndRead;
  // the new result replaces it.
  if (in_read_) EndRead();
  log_.push_back(Record{c.value, selected_, false});
  current_ = log_.size() - 1;
  has_data_ = true;
  shift_ = static_cast<std::uint32_t>(c.value) & 0xFFFFFFu;
}

void FakeHx711::Update() {
  const std::int64_t now = time_.now_ns;
  const bool power_down = powered_ && clock_high_ && now - rise_ns_ > kPowerDownPulseNs;
  const std::int64_t until = power_down ? rise_ns_ + kPowerDownPulseNs : now;
  while (powered_ && next_done_ns_ <= until) Complete(next_done_ns_);
  if (power_down) {
    powered_ = false;
    ++power_downs_;
    has_data_ = false;
    in_read_ = false;
    read_pulses_ = 0;
    next_done_ns_ = kNever;
  }
  NoteLevel();
}

bool FakeHx711::Level() const {
  if (stuck_high_) return true;
  if (stuck_low_) return false;
  if (!powered_) return true;
  if (has_data_) {
    if (!in_read_ || read_pulses_ == 0) return false;    // data ready
    return ((shift_ >> (24 - read_pulses_)) & 1u) != 0;  // bit 23 after the 1st rising edge
  }
  return true;
}

void FakeHx711::NoteLevel() {
  const bool level = Level();
  if (level != last_level_) edges_.push_back(level);
  last_level_ = level;
}

void FakeHx711::OnClock(bool high) {
  Update();
  const std::int64_t now = time_.now_ns;
  if (high) {
    clock_high_ = true;
    rise_ns_ = now;
    if (powered_ && (has_data_ || in_read_)) {
      if (!in_read_) {
        in_read_ = true;
        read_pulses_ = 0;
      }
      ++read_pulses_;
      if (read_pulses_ == 24) log_[current_].shifted_out = true;
      if (read_pulses_ == 25) has_data_ = false;  // DOUT back high until the next result
      if (read_pulses_ > 27) ++violations_;
    } else if (powered_) {
      stray_ = true;
    }
  } else {
    clock_high_ = false;
    if (!powered_) {
      // PD_SCK low after a power-down: reset, default input, conversions start over.
      powered_ = true;
      ++resets_;
      selected_ = Input::kA128;
      has_data_ = false;
      in_read_ = false;
      read_pulses_ = 0;
      last_done_ns_ = now;
      next_done_ns_ = kNever;
      Reschedule();
    } else if (stray_) {
      ++violations_;  // a short pulse while no result was ready
    }
    stray_ = false;
  }
  NoteLevel();
}

Status FakeHx711::DoGet(bool& high) {
  if (fail_gets_at_ >= 0 && gets_++ == fail_gets_at_) return Status::kReadError;
  time_.now_ns += get_cost_ns_;
  Update();
  high = Level();
  return Status::kOk;
}

Status FakeHx711::DoWaitForEdge(std::uint32_t timeout_us, bool& rising) {
  Update();
  const std::int64_t deadline = time_.now_ns + std::int64_t{timeout_us} * 1000;
  for (int i = 0; i < 4; ++i) {
    if (!edges_.empty()) {
      rising = edges_.front();
      edges_.pop_front();
      return Status::kOk;
    }
    // Without clock activity DOUT changes only when a conversion completes or the chip powers down.
    std::int64_t next = kNever;
    if (!stuck_high_ && !stuck_low_ && powered_ && Level()) next = next_done_ns_;
    if (powered_ && clock_high_) next = std::min(next, rise_ns_ + kPowerDownPulseNs + 1);
    time_.now_ns = std::max(time_.now_ns, std::min(next, deadline));
    Update();
    if (next > deadline) break;
  }
  if (!edges_.empty()) {
    rising = edges_.front();
    edges_.pop_front();
    return Status::kOk;
  }
  return Status::kTimeout;
}

Status FakeHx711::DoDiscardEdges() {
  Update();
  edges_.clear();
  return Status::kOk;
}

}  // namespace ftstack::test
