// ftd's recording logger: a lock-free ring filled by the sampling thread, drained into a CSV.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "firmware/device.hpp"

namespace ftstack {
class RecordingWriter;
}  // namespace ftstack

namespace ftstack::daemon {

/// Single-producer (the sampling thread: Push) single-consumer (the owner: Drain) log of
/// published samples. Off until Open.
class SampleLog {
 public:
  SampleLog();
  ~SampleLog();
  SampleLog(const SampleLog&) = delete;
  SampleLog& operator=(const SampleLog&) = delete;

  /// Checks that `path` can be written (throws FtdError) and sizes the ring; the recording's
  /// header and `metadata` are written with the first row.
  /// `time_scale` multiplies the sample times into the log's `t`: the paced simulator's
  /// --sim-speed (its conversion times are wall-clock µs; t is then simulated time), else 1.
  void Open(const std::string& path, std::vector<std::string> metadata, double time_scale = 1.0);
  [[nodiscard]] bool enabled() const { return !ring_.empty(); }
  /// Sampling thread: queues one published sample; counts it dropped when the ring is full.
  void Push(const fw::DeviceSample& sample);
  /// Owner thread: writes the queued rows (bridges in mV/V from the converter's scaling).
  void Drain(const hal::AdcInfo& adc);
  /// Flushes the written rows to the file.
  void Flush();

  [[nodiscard]] std::uint64_t logged_rows() const { return logged_rows_; }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::string path_;
  std::vector<std::string> metadata_;
  std::unique_ptr<RecordingWriter> writer_;
  std::vector<fw::DeviceSample> ring_;
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::uint64_t logged_rows_ = 0;
  std::uint64_t time_base_us_ = 0;  ///< added to the 32-bit µs timestamp after each wrap
  std::uint32_t last_timestamp_us_ = 0;
  double time_scale_ = 1.0;
};

}  // namespace ftstack::daemon
