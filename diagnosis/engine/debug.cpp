#include "diagnosis/engine/debug.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace ftstack::diag {

bool DebugOn() {
  static const bool on = std::getenv("FTDIAG_DEBUG") != nullptr;
  return on;
}

namespace {

/// kB of a line "Key:   N kB" of /proc/self/status (0 when absent).
long StatusKb(const char* key) {
  long kb = 0;
  if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    const std::size_t len = std::strlen(key);
    while (std::fgets(line, sizeof line, f) != nullptr) {
      if (std::strncmp(line, key, len) == 0) kb = std::atol(line + len);
    }
    std::fclose(f);
  }
  return kb;
}

}  // namespace

void DebugTime(const char* stage, const char* what, std::chrono::steady_clock::time_point t0) {
  if (!DebugOn()) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Resident now, and the peak since the previous line (the high-water mark is reset after
  // reading it; with --threads 1 it is the peak of this one fit).
  const long now_kb = StatusKb("VmRSS:");
  const long hwm_kb = StatusKb("VmHWM:");
  if (std::FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
  std::fprintf(stderr, "time %-8s %-40s %7.3f s (RSS %ld MB, peak since last %ld MB)\n", stage,
               what, s, now_kb / 1024, hwm_kb / 1024);
}

}  // namespace ftstack::diag
