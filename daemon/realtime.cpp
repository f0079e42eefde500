#include "daemon/realtime.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace ftstack::daemon {
namespace {

std::string ErrnoText(int err) {
  char buf[128];
  return strerror_r(err, buf, sizeof buf);  // GNU: returns the message
}

std::string LimitText(int resource, const char* unit, unsigned long long divisor) {
  rlimit lim{};
  if (getrlimit(resource, &lim) != 0) return "unknown";
  if (lim.rlim_cur == RLIM_INFINITY) return "unlimited";
  return std::to_string(static_cast<unsigned long long>(lim.rlim_cur) / divisor) + unit;
}

}  // namespace

std::string LockMemory() {
  rlimit lim{};
  const bool unlimited = getrlimit(RLIMIT_MEMLOCK, &lim) == 0 && lim.rlim_cur == RLIM_INFINITY;
  if (geteuid() != 0 && !unlimited) {
    return "memory not locked (not root and RLIMIT_MEMLOCK is " +
           LimitText(RLIMIT_MEMLOCK, " kB", 1024) + ")";
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return "memory not locked (mlockall: " + ErrnoText(errno) + ")";
  }
  return "memory locked";
}

std::string MakeRealtime(pthread_t thread, bool* ok) {
  *ok = false;
  int priority = kSamplingPriority;
  rlimit lim{};
  if (geteuid() != 0 && getrlimit(RLIMIT_RTPRIO, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY &&
      lim.rlim_cur < static_cast<rlim_t>(priority)) {
    priority = static_cast<int>(lim.rlim_cur);
  }
  if (priority < sched_get_priority_min(SCHED_FIFO)) {
    return "default scheduler, not real-time (not root and RLIMIT_RTPRIO is " +
           LimitText(RLIMIT_RTPRIO, "", 1) + ")";
  }
  sched_param param{};
  param.sched_priority = priority;
  const int err = pthread_setschedparam(thread, SCHED_FIFO, &param);
  if (err != 0) {
    return "default scheduler, not real-time (SCHED_FIFO: " + ErrnoText(err) +
           "; RLIMIT_RTPRIO is " + LimitText(RLIMIT_RTPRIO, "", 1) + ")";
  }
  *ok = true;
  return "real-time (SCHED_FIFO priority " + std::to_string(priority) + ")";
}

}  // namespace ftstack::daemon
