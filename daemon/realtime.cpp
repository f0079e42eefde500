#include "daemon/realtime.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>

namespace ftstack::daemon {

bool SizeThreadStacks() {
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer's runtime needs more stack per thread than the sized stacks give: thread
  // creation then fails with EINVAL. Keep the default size under it.
  return false;
#else
  pthread_attr_t attr;
  if (pthread_attr_init(&attr) != 0) return false;
  const bool ok = pthread_attr_setstacksize(&attr, kThreadStackBytes) == 0 &&
                  pthread_setattr_default_np(&attr) == 0;
  pthread_attr_destroy(&attr);
  return ok;
#endif
}
namespace {

constexpr int kCapIpcLock = 14;  // linux/capability.h
constexpr int kCapSysNice = 23;

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

/// Whether this process holds capability `bit` (CapEff in /proc/self/status): root in a
/// container may lack CAP_SYS_NICE or CAP_IPC_LOCK, a user may have been granted them.
bool HasCapability(int bit) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("CapEff:", 0) != 0) continue;
    try {
      return ((std::stoull(line.substr(7), nullptr, 16) >> bit) & 1u) != 0;
    } catch (const std::exception&) {
      return false;
    }
  }
  return false;
}

/// VmLck of this process in kB (/proc/self/status), -1 when unreadable.
long LockedKb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmLck:", 0) != 0) continue;
    try {
      return std::stol(line.substr(6));
    } catch (const std::exception&) {
      return -1;
    }
  }
  return -1;
}

}  // namespace

std::string LockMemory() {
  rlimit lim{};
  const bool unlimited = getrlimit(RLIMIT_MEMLOCK, &lim) == 0 && lim.rlim_cur == RLIM_INFINITY;
  // With a limited lock, MCL_FUTURE would make allocations beyond the limit fail later: lock
  // only when nothing limits it.
  if (!unlimited && !HasCapability(kCapIpcLock)) {
    return "memory not locked (no CAP_IPC_LOCK and RLIMIT_MEMLOCK is " +
           LimitText(RLIMIT_MEMLOCK, " kB", 1024) + ")";
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return "memory not locked (mlockall: " + ErrnoText(errno) + ")";
  }
  // Said only when the kernel shows it: AddressSanitizer, for one, makes mlockall a no-op that
  // returns 0.
  if (LockedKb() == 0) return "memory not locked (mlockall had no effect: VmLck 0 kB)";
  return "memory locked";
}

std::string MakeRealtime(pthread_t thread, bool* ok) {
  *ok = false;
  int priority = kSamplingPriority;
  if (!HasCapability(kCapSysNice)) {
    rlimit lim{};
    if (getrlimit(RLIMIT_RTPRIO, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY &&
        lim.rlim_cur < static_cast<rlim_t>(priority)) {
      priority = static_cast<int>(lim.rlim_cur);
    }
    if (priority < sched_get_priority_min(SCHED_FIFO)) {
      return "default scheduler, not real-time (no CAP_SYS_NICE and RLIMIT_RTPRIO is " +
             LimitText(RLIMIT_RTPRIO, "", 1) + ")";
    }
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
