// Single-writer seqlock: publishes the latest value of a trivially copyable type to many readers.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace ftstack::fw {

/// Latest-value exchange between one writer (the sampling thread) and any number of readers (the
/// Modbus threads). The writer never blocks and never waits for a reader; a reader copies a value
/// that was complete at one instant (it retries while a write overlaps its copy), so nothing
/// queues up and no read mixes two writes.
///
/// The payload lives in relaxed atomic words, so the concurrent copy is well defined C++ (no data
/// race for ThreadSanitizer to report); the sequence counter orders it (odd = write in progress).
template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "Seqlock payload must be trivially copyable");

 public:
  Seqlock() {
    const T zero{};
    Write(zero);
    seq_.store(0, std::memory_order_relaxed);
  }

  /// Publishes `value`. Only one thread may call Write.
  void Write(const T& value) {
    std::array<std::uint32_t, kWords> words{};
    std::memcpy(words.data(), &value, sizeof(T));
    const std::uint32_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) data_[i].store(words[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Copies the latest complete value into *out. Retries at most `max_attempts` times while the
  /// writer overlaps; returns false (and leaves *out untouched) if it never got a clean copy.
  [[nodiscard]] bool Read(T* out, unsigned max_attempts = 1000) const {
    std::array<std::uint32_t, kWords> words{};
    for (unsigned attempt = 0; attempt < max_attempts; ++attempt) {
      const std::uint32_t s0 = seq_.load(std::memory_order_acquire);
      if ((s0 & 1u) != 0) continue;
      for (std::size_t i = 0; i < kWords; ++i) words[i] = data_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s0) {
        std::memcpy(static_cast<void*>(out), words.data(), sizeof(T));
        return true;
      }
    }
    return false;
  }

  /// Number of completed writes (wraps).
  [[nodiscard]] std::uint32_t writes() const { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 3) / 4;
  std::atomic<std::uint32_t> seq_{0};
  std::array<std::atomic<std::uint32_t>, kWords> data_{};
};

}  // namespace ftstack::fw
