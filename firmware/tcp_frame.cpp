#include "firmware/tcp_frame.hpp"

#include <cstring>

namespace ftstack::fw {

namespace {

[[nodiscard]] std::uint16_t Be16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

}  // namespace

bool TcpFrameAssembler::Commit(std::size_t n) {
  if (n > space_size()) return false;
  fill_ += n;
  return true;
}

std::size_t TcpFrameAssembler::Append(const std::uint8_t* data, std::size_t n) {
  const std::size_t k = n < space_size() ? n : space_size();
  if (k > 0) std::memcpy(space(), data, k);
  fill_ += k;
  return k;
}

FrameState TcpFrameAssembler::Next() const {
  if (fill_ < kMbapLength) return FrameState::kNeedMore;
  const std::uint16_t protocol = Be16(&buf_[2]);
  const std::uint16_t length = Be16(&buf_[4]);
  if (protocol != 0 || length < 2 || length > kMaxTcpAdu - 6) return FrameState::kBadHeader;
  return fill_ >= 6u + length ? FrameState::kFrame : FrameState::kNeedMore;
}

std::size_t TcpFrameAssembler::frame_length() const { return 6u + Be16(&buf_[4]); }

void TcpFrameAssembler::Pop() {
  if (Next() != FrameState::kFrame) return;
  const std::size_t total = frame_length();
  std::memmove(buf_.data(), buf_.data() + total, fill_ - total);
  fill_ -= total;
}

}  // namespace ftstack::fw
