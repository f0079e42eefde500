// Bridge outputs of a long simulated recording served to the simulated converter while a thread
// composes the next piece.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>

#include "hal/sim/sim_adc.hpp"
#include "sim/piecewise_compose.hpp"

namespace ftstack::sim {

/// Reads a PiecewiseComposition at each conversion's time (the nearest row; after the last row
/// the last one holds). The piece after the one being read is composed ahead on a thread of its
/// own, so the converter's thread only swaps pointers in the usual forward run (it waits only on
/// a jump or when composing is slower than converting). At most three pieces exist at once: the
/// one read, the one ready, the one being composed.
class StreamedBridges final : public hal::sim::BridgeSignalSource {
 public:
  StreamedBridges(std::unique_ptr<PiecewiseComposition> composition, double rate_hz);
  ~StreamedBridges() override;
  StreamedBridges(const StreamedBridges&) = delete;
  StreamedBridges& operator=(const StreamedBridges&) = delete;

  [[nodiscard]] std::uint8_t channel_count() const override { return channels_; }
  [[nodiscard]] bool Sample(double t_s, double* bridge_mvv, double* temperature_c) override;

 private:
  void ComposeAhead();
  /// Makes piece `index` the current one (waits for the composer if it is not ready).
  void Switch(std::size_t index);

  std::unique_ptr<PiecewiseComposition> composition_;
  double rate_hz_;
  std::uint8_t channels_;
  std::unique_ptr<ComposedPiece> current_;
  std::size_t current_index_ = 0;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::unique_ptr<ComposedPiece> ready_;  // guarded by mutex_
  std::size_t ready_index_ = 0;           // guarded by mutex_
  std::size_t wanted_index_ = 0;          // guarded by mutex_: the piece to compose next
  std::unique_ptr<ComposedPiece> spent_;  // guarded by mutex_: freed by the composer's thread
  bool stop_ = false;                     // guarded by mutex_
  std::thread composer_;
};

}  // namespace ftstack::sim
