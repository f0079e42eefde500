// FTDIAG_DEBUG output of the diagnosis: time and memory of every fit and stage, on stderr.
#pragma once

#include <chrono>

namespace ftstack::diag {

/// Whether the environment variable FTDIAG_DEBUG is set (read once).
[[nodiscard]] bool DebugOn();
/// With FTDIAG_DEBUG: "time STAGE WHAT seconds since t0 (RSS now, peak since the previous line)".
/// The peak is the kernel's high-water mark, reset after each line (/proc/self/clear_refs): with
/// --threads 1 it is one fit's peak, and the process's own peak (GNU time %M) is then only the
/// last interval's, so measure the peak without FTDIAG_DEBUG.
void DebugTime(const char* stage, const char* what, std::chrono::steady_clock::time_point t0);

}  // namespace ftstack::diag
