// Real-time set-up of ftd's sampling thread (SCHED_FIFO, locked memory) and its one-line report.
#pragma once

#include <pthread.h>

#include <cstddef>
#include <string>

namespace ftstack::daemon {

/// SCHED_FIFO priority asked for the sampling thread (capped at RLIMIT_RTPRIO without
/// CAP_SYS_NICE).
inline constexpr int kSamplingPriority = 50;

/// Stack of each thread ftd starts. Locked memory locks stacks whole (the default is
/// RLIMIT_STACK, 8 MiB each); the deepest thread (a Modbus reply: one input image and one
/// published sample on its stack, libmodbus's frame buffers) needs a few KiB.
inline constexpr std::size_t kThreadStackBytes = 256 * 1024;

/// Makes kThreadStackBytes the stack size of every thread created after it (std::thread too).
/// Returns false where the C library refuses.
[[nodiscard]] bool SizeThreadStacks();

/// Locks the process's memory (mlockall, current and future) where the system permits it: with
/// CAP_IPC_LOCK or an unlimited RLIMIT_MEMLOCK (a limited lock would make later allocations fail).
/// Returns the clause for the report: "memory locked" or why not.
[[nodiscard]] std::string LockMemory();

/// Puts `thread` under SCHED_FIFO at kSamplingPriority (or the RLIMIT_RTPRIO cap). Returns the
/// clause for the report: "real-time (SCHED_FIFO priority N)" or why not.
[[nodiscard]] std::string MakeRealtime(pthread_t thread, bool* ok);

}  // namespace ftstack::daemon
