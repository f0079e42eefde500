// Test helper for the soaks: their length from the environment and a process's resident memory.
#pragma once

#include <sys/types.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace ftstack::test {

/// Seconds a soak runs: FTSTACK_SOAK_SECONDS when set and positive, else 5 (CI's length).
inline double SoakSeconds() {
  const char* s = std::getenv("FTSTACK_SOAK_SECONDS");
  const double v = s != nullptr ? std::atof(s) : 5.0;
  return v > 0 ? v : 5.0;
}

/// Resident memory of a process, kB (VmRSS of /proc/PID/status); -1 when unreadable.
inline long VmRssKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  }
  return -1;
}

}  // namespace ftstack::test
