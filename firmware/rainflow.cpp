#include "firmware/rainflow.hpp"

namespace ftstack::fw {
namespace {

[[nodiscard]] std::int64_t Range(std::int32_t a, std::int32_t b) {
  const std::int64_t d = std::int64_t{a} - b;
  return d < 0 ? -d : d;
}

}  // namespace

bool RainflowCounter::Add(std::int32_t v) {
  if (!started_) {
    started_ = true;
    extreme_ = v;
    return Push(v);
  }
  if (dir_ == 0) {
    if (Range(v, residue_[n_ - 1]) > gate_) {
      dir_ = v > residue_[n_ - 1] ? 1 : -1;
      extreme_ = v;
    }
    return false;
  }
  if ((dir_ > 0 && v > extreme_) || (dir_ < 0 && v < extreme_)) {
    extreme_ = v;
  } else if (Range(v, extreme_) > gate_) {
    const bool closed = Push(extreme_);  // the extreme was a turning point
    dir_ = -dir_;
    extreme_ = v;
    return closed;
  }
  return false;
}

bool RainflowCounter::Push(std::int32_t p) {
  bool closed = false;
  if (n_ == kResidue) {  // forget the oldest point
    for (std::size_t i = 1; i < n_; ++i) residue_[i - 1] = residue_[i];
    --n_;
  }
  residue_[n_++] = p;
  while (n_ >= 4) {
    const std::int32_t a = residue_[n_ - 4], b = residue_[n_ - 3];
    const std::int32_t c = residue_[n_ - 2], d = residue_[n_ - 1];
    const std::int64_t x = Range(b, c);
    if (x > Range(a, b) || x > Range(c, d)) break;
    if (x >= count_range_ && cycles_ < UINT32_MAX) ++cycles_;
    std::size_t bin = 0;
    while (bin < edges_.size() && x >= edges_[bin]) ++bin;
    if (bins_[bin] < UINT32_MAX) ++bins_[bin];
    closed = true;
    residue_[n_ - 3] = d;
    n_ -= 2;
  }
  return closed;
}

}  // namespace ftstack::fw
