// Modbus TCP frame assembly: bytes as a stream delivers them → whole MBAP frames (no heap).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ftstack::fw {

/// Largest Modbus ADU: 7-byte MBAP header + 253-byte PDU.
inline constexpr std::size_t kMaxTcpAdu = 260;
/// MBAP header: transaction id, protocol id, length, unit id.
inline constexpr std::size_t kMbapLength = 7;

/// What the buffered bytes hold.
enum class FrameState : std::uint8_t {
  kNeedMore = 0,  ///< no complete frame yet (fewer than a header, or the frame is still short)
  kFrame,         ///< a complete frame: frame() / frame_length() until Pop()
  kBadHeader,  ///< protocol id ≠ 0 or length outside 2 … 254: the stream cannot resynchronise
};

/// Assembles Modbus TCP frames of one connection from reads of any size. Fixed buffer of one
/// maximal ADU; a frame never exceeds it (the header's length field is checked first).
class TcpFrameAssembler {
 public:
  /// Where the next received bytes go, and how many fit.
  [[nodiscard]] std::uint8_t* space() { return buf_.data() + fill_; }
  [[nodiscard]] std::size_t space_size() const { return buf_.size() - fill_; }
  /// Records `n` (≤ space_size()) bytes written into space(); false (nothing recorded) otherwise.
  [[nodiscard]] bool Commit(std::size_t n);
  /// Copies up to space_size() bytes in (for callers that do not read into space()).
  std::size_t Append(const std::uint8_t* data, std::size_t n);

  /// Looks at the front of the buffer.
  [[nodiscard]] FrameState Next() const;
  /// The complete frame at the front (valid after Next() == kFrame, until Pop()).
  [[nodiscard]] const std::uint8_t* frame() const { return buf_.data(); }
  [[nodiscard]] std::size_t frame_length() const;
  [[nodiscard]] std::uint8_t unit() const { return buf_[6]; }
  /// Drops the front frame (after Next() == kFrame).
  void Pop();

  /// A complete frame or a header to refuse is buffered (no new data will announce it).
  [[nodiscard]] bool Pending() const { return Next() != FrameState::kNeedMore; }
  [[nodiscard]] std::size_t fill() const { return fill_; }
  void Reset() { fill_ = 0; }

 private:
  std::array<std::uint8_t, kMaxTcpAdu> buf_{};
  std::size_t fill_ = 0;
};

}  // namespace ftstack::fw
