// A minimal fork-join loop for the diagnosis's independent fits (host code: std::thread).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace ftstack::diag {

/// Worker threads for `requested` (0: the machine's hardware threads, at most 4; ≥ 1).
inline int ResolveThreads(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return static_cast<int>(std::clamp(hw, 1U, 4U));
}

/// Bytes that work run side by side may hold beyond what one thread of it holds: a fit's own
/// copies of the record's series. Over this the work runs one by one, which keeps the peak of the
/// largest records where one thread puts it.
inline constexpr double kSideBySideBytes = 64.0 * 1024 * 1024;

/// The threads for work of which each extra thread holds `bytes_per_thread` more: `threads` while
/// the extra threads' bytes fit in kSideBySideBytes, else 1.
[[nodiscard]] inline int SideBySide(int threads, double bytes_per_thread) {
  return bytes_per_thread * (threads - 1) <= kSideBySideBytes ? threads : 1;
}

/// Calls fn(k) for k = 0 … n − 1 on up to `threads` threads (the caller's among them), each index
/// once, in the order k = 0, 1, … of being taken. The first exception thrown by fn is rethrown
/// here after every thread has joined (the remaining indices are skipped).
template <class F>
void ParallelFor(std::size_t n, int threads, F&& fn) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mu;
  auto work = [&] {
    for (std::size_t k = next++; k < n; k = next++) {
      try {
        fn(k);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mu);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  const std::size_t extra =
      std::min<std::size_t>(n, static_cast<std::size_t>(std::max(threads, 1)));
  for (std::size_t t = 1; t < extra; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace ftstack::diag
