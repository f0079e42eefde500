// Real-time scheduling for a bit-banging reading thread (SCHED_FIFO, locked memory).
#pragma once

#include <cstddef>

#include "hal/adc.hpp"

namespace ftstack::hal {

/// Puts the calling thread under SCHED_FIFO at `priority` (1 … 99) and, with lock_memory, locks the
/// process's memory, so a clock pulse is not stretched by preemption or a page fault. priority 0
/// does nothing. A failing mlockall is reported in `error` but still returns kOk.
/// kOk; kInvalidArgument for a priority outside 0 … 99; kUnavailable without the right
/// (CAP_SYS_NICE / RLIMIT_RTPRIO), with the reason in error[0 … error_size).
[[nodiscard]] Status EnterRealtime(int priority, bool lock_memory, char* error,
                                   std::size_t error_size);

}  // namespace ftstack::hal
