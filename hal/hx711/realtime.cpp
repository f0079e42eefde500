#include "hal/hx711/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "hal/errno_text.hpp"

namespace ftstack::hal {

Status EnterRealtime(int priority, bool lock_memory, char* error, std::size_t error_size) {
  if (error != nullptr && error_size > 0) error[0] = '\0';
  if (priority == 0) return Status::kOk;
  if (priority < 1 || priority > 99) {
    if (error != nullptr) {
      std::snprintf(error, error_size, "real-time priority %d not in 1…99", priority);
    }
    return Status::kInvalidArgument;
  }
  sched_param sp{};
  sp.sched_priority = priority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (err != 0) {
    if (error != nullptr) {
      std::snprintf(error, error_size,
                    "SCHED_FIFO priority %d: %s (needs CAP_SYS_NICE or RLIMIT_RTPRIO)", priority,
                    hal::ErrnoText(err).c_str());
    }
    return Status::kUnavailable;
  }
  if (lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0 && error != nullptr) {
    // Scheduling is in place; unlocked memory only risks page-fault delays. Report, succeed.
    std::snprintf(error, error_size, "mlockall: %s (memory not locked)",
                  hal::ErrnoText(errno).c_str());
  }
  return Status::kOk;
}

}  // namespace ftstack::hal
