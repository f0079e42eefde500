// The Linux CLOCK_MONOTONIC implementation of gpio::Clock used with real hardware.
#pragma once

#include <time.h>

#include <cstdint>

#include "hal/gpio/line.hpp"

namespace ftstack::hal::gpio {

/// gpio::Clock on CLOCK_MONOTONIC (immune to wall-clock steps).
class SystemClock final : public Clock {
 public:
  [[nodiscard]] std::int64_t NowNs() override {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
  }
  void SleepNs(std::int64_t ns) override {
    if (ns <= 0) return;
    const std::int64_t until = NowNs() + ns;
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(until / 1000000000LL);
    ts.tv_nsec = static_cast<long>(until % 1000000000LL);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
    }
  }
};

}  // namespace ftstack::hal::gpio
