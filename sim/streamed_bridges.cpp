#include "sim/streamed_bridges.hpp"

#include <cmath>
#include <utility>

namespace ftstack::sim {

StreamedBridges::StreamedBridges(std::unique_ptr<PiecewiseComposition> composition, double rate_hz)
    : composition_(std::move(composition)), rate_hz_(rate_hz) {
  current_ = std::make_unique<ComposedPiece>(composition_->Compose(0));
  channels_ = static_cast<std::uint8_t>(current_->mvv.rows());
  wanted_index_ = 1;
  composer_ = std::thread([this] { ComposeAhead(); });
}

StreamedBridges::~StreamedBridges() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  composer_.join();
}

void StreamedBridges::ComposeAhead() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] {
      return stop_ || spent_ != nullptr ||
             (wanted_index_ < composition_->pieces() &&
              (ready_ == nullptr || ready_index_ != wanted_index_));
    });
    if (stop_) return;
    std::unique_ptr<ComposedPiece> old = std::move(spent_);
    if (ready_ != nullptr && ready_index_ != wanted_index_) old = std::move(ready_);
    const std::size_t index = wanted_index_;
    const bool compose = index < composition_->pieces() && ready_ == nullptr;
    lock.unlock();
    old.reset();
    std::unique_ptr<ComposedPiece> piece;
    if (compose) piece = std::make_unique<ComposedPiece>(composition_->Compose(index));
    lock.lock();
    if (piece != nullptr && ready_ == nullptr && wanted_index_ == index) {
      ready_ = std::move(piece);
      ready_index_ = index;
      changed_.notify_all();
    }
    // A piece composed for a wish that changed meanwhile is dropped (outside the lock).
    if (piece != nullptr) {
      lock.unlock();
      piece.reset();
      lock.lock();
    }
  }
}

void StreamedBridges::Switch(std::size_t index) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!(ready_ != nullptr && ready_index_ == index)) {
    wanted_index_ = index;
    changed_.notify_all();
    changed_.wait(lock, [this, index] { return ready_ != nullptr && ready_index_ == index; });
  }
  spent_ = std::move(current_);
  current_ = std::move(ready_);
  current_index_ = index;
  wanted_index_ = index + 1;
  changed_.notify_all();
}

bool StreamedBridges::Sample(double t_s, double* bridge_mvv, double* temperature_c) {
  const double at = std::floor(t_s * rate_hz_ + 0.5);
  const std::size_t last = composition_->rows() - 1;
  const std::size_t row =
      at <= 0 ? 0 : (at >= static_cast<double>(last) ? last : static_cast<std::size_t>(at));
  const std::size_t index = row / composition_->piece_rows();
  if (index != current_index_) Switch(index);
  const auto col = static_cast<Eigen::Index>(row - current_->first_row);
  for (Eigen::Index c = 0; c < current_->mvv.rows(); ++c) bridge_mvv[c] = current_->mvv(c, col);
  if (temperature_c != nullptr) *temperature_c = current_->temp_c[static_cast<std::size_t>(col)];
  return true;
}

}  // namespace ftstack::sim
