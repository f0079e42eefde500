#include "hal/gpio/gpiod_v1_chip.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "hal/errno_text.hpp"

namespace ftstack::hal::gpio {
namespace {

timespec ToTimespec(std::uint32_t timeout_us) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(timeout_us / 1000000u);
  ts.tv_nsec = static_cast<long>(timeout_us % 1000000u) * 1000L;
  return ts;
}

}  // namespace

Status GpiodV1OutputLine::DoSet(bool high) {
  return gpiod_line_set_value(line_, high ? 1 : 0) == 0 ? Status::kOk : Status::kReadError;
}

Status GpiodV1InputLine::DoGet(bool& high) {
  const int v = gpiod_line_get_value(line_);
  if (v < 0) return Status::kReadError;
  high = v != 0;
  return Status::kOk;
}

Status GpiodV1InputLine::DoWaitForEdge(std::uint32_t timeout_us, bool& rising) {
  if (edges_ == Edge::kNone) return Status::kNotConfigured;
  const timespec ts = ToTimespec(timeout_us);
  const int r = gpiod_line_event_wait(line_, &ts);
  if (r == 0) return Status::kTimeout;
  if (r < 0) return Status::kReadError;
  gpiod_line_event ev{};
  if (gpiod_line_event_read(line_, &ev) != 0) return Status::kReadError;
  rising = ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
  return Status::kOk;
}

Status GpiodV1InputLine::DoDiscardEdges() {
  if (edges_ == Edge::kNone) return Status::kOk;
  // The kernel queues at most 16 events per line in the v1 ABI; bound the loop anyway.
  for (int i = 0; i < 256; ++i) {
    const timespec zero{};
    const int r = gpiod_line_event_wait(line_, &zero);
    if (r == 0) return Status::kOk;
    if (r < 0) return Status::kReadError;
    gpiod_line_event ev{};
    if (gpiod_line_event_read(line_, &ev) != 0) return Status::kReadError;
  }
  return Status::kOk;
}

GpiodV1Chip::~GpiodV1Chip() {
  for (std::size_t i = 0; i < output_count_; ++i) gpiod_line_release(outputs_[i].line_);
  for (std::size_t i = 0; i < input_count_; ++i) gpiod_line_release(inputs_[i].line_);
  if (chip_ != nullptr) gpiod_chip_close(chip_);
}

Status GpiodV1Chip::Open(const char* path, const char* consumer) {
  if (chip_ != nullptr) {
    std::snprintf(error_.data(), error_.size(), "gpiochip %s: already open", path_.data());
    return Status::kInvalidArgument;
  }
  std::snprintf(path_.data(), path_.size(), "%s", path != nullptr ? path : "");
  consumer_ = consumer != nullptr ? consumer : "ftstack";
  errno = 0;
  chip_ = path_[0] == '/' ? gpiod_chip_open(path_.data()) : gpiod_chip_open_lookup(path_.data());
  if (chip_ == nullptr) {
    const int err = errno != 0 ? errno : ENODEV;
    std::snprintf(error_.data(), error_.size(), "cannot open GPIO chip %s: %s", path_.data(),
                  err == ENOTTY || err == EINVAL ? "not a GPIO character device"
                                                 : hal::ErrnoText(err).c_str());
    return Status::kUnavailable;
  }
  error_[0] = '\0';
  return Status::kOk;
}

Status GpiodV1Chip::Fail(const char* what, std::uint32_t offset, int err) {
  std::snprintf(error_.data(), error_.size(), "GPIO chip %s line %u: %s: %s", path_.data(),
                static_cast<unsigned>(offset), what, hal::ErrnoText(err).c_str());
  return Status::kUnavailable;
}

Status GpiodV1Chip::GetLine(std::uint32_t offset, std::size_t used, std::size_t capacity,
                            gpiod_line** line) {
  if (chip_ == nullptr) return Fail("cannot request", offset, ENODEV);
  if (used >= capacity) {
    std::snprintf(error_.data(), error_.size(), "GPIO chip %s: more than %u lines of one direction",
                  path_.data(), static_cast<unsigned>(capacity));
    return Status::kInvalidArgument;
  }
  errno = 0;
  *line = gpiod_chip_get_line(chip_, offset);
  if (*line == nullptr) return Fail("no such line", offset, errno != 0 ? errno : EINVAL);
  return Status::kOk;
}

Status GpiodV1Chip::DoRequestOutput(std::uint32_t offset, bool initial_high, OutputLine** line) {
  gpiod_line* l = nullptr;
  if (const Status s = GetLine(offset, output_count_, outputs_.size(), &l); s != Status::kOk) {
    return s;
  }
  if (gpiod_line_request_output(l, consumer_, initial_high ? 1 : 0) != 0) {
    return Fail("cannot request as output", offset, errno);
  }
  GpiodV1OutputLine& slot = outputs_[output_count_++];
  slot.line_ = l;
  *line = &slot;
  return Status::kOk;
}

Status GpiodV1Chip::DoRequestInput(std::uint32_t offset, Edge edges, InputLine** line) {
  gpiod_line* l = nullptr;
  if (const Status s = GetLine(offset, input_count_, inputs_.size(), &l); s != Status::kOk) {
    return s;
  }
  int r = 0;
  switch (edges) {
    case Edge::kNone:
      r = gpiod_line_request_input(l, consumer_);
      break;
    case Edge::kRising:
      r = gpiod_line_request_rising_edge_events(l, consumer_);
      break;
    case Edge::kFalling:
      r = gpiod_line_request_falling_edge_events(l, consumer_);
      break;
    case Edge::kBoth:
      r = gpiod_line_request_both_edges_events(l, consumer_);
      break;
  }
  if (r != 0) return Fail("cannot request as input", offset, errno);
  GpiodV1InputLine& slot = inputs_[input_count_++];
  slot.line_ = l;
  slot.edges_ = edges;
  *line = &slot;
  return Status::kOk;
}

}  // namespace ftstack::hal::gpio
