// Modbus TCP frame assembly: frames out of byte-by-byte and coalesced reads, bad headers refused.
#include <gtest/gtest.h>

#include <vector>

#include "firmware/tcp_frame.hpp"

namespace ftstack::fw {
namespace {

std::vector<std::uint8_t> Frame(std::uint16_t tid, std::uint8_t unit,
                                const std::vector<std::uint8_t>& pdu) {
  const auto len = static_cast<std::uint16_t>(pdu.size() + 1);
  std::vector<std::uint8_t> f(7 + pdu.size(), 0);
  f[0] = static_cast<std::uint8_t>(tid >> 8);
  f[1] = static_cast<std::uint8_t>(tid & 0xFF);
  f[4] = static_cast<std::uint8_t>(len >> 8);
  f[5] = static_cast<std::uint8_t>(len & 0xFF);
  f[6] = unit;
  for (std::size_t i = 0; i < pdu.size(); ++i) f[7 + i] = pdu[i];
  return f;
}

TEST(TcpFrame, ByteByByteAndCoalescedReadsGiveTheSameFrames) {
  const auto a = Frame(1, 1, {4, 0, 0, 0, 74});
  const auto b = Frame(2, 255, {16, 0, 1, 0, 2, 4, 0, 1, 0, 2});
  std::vector<std::uint8_t> stream = a;
  for (std::uint8_t x : b) stream.push_back(x);
  for (std::size_t step : {std::size_t{1}, std::size_t{5}, stream.size()}) {
    TcpFrameAssembler asm_;
    std::vector<std::vector<std::uint8_t>> got;
    for (std::size_t at = 0; at < stream.size(); at += step) {
      const std::size_t n = std::min(step, stream.size() - at);
      ASSERT_EQ(asm_.Append(stream.data() + at, n), n);
      while (asm_.Next() == FrameState::kFrame) {
        got.emplace_back(asm_.frame(), asm_.frame() + asm_.frame_length());
        asm_.Pop();
      }
      EXPECT_EQ(asm_.Next(), FrameState::kNeedMore);
    }
    ASSERT_EQ(got.size(), 2u) << "step " << step;
    EXPECT_EQ(got[0], a);
    EXPECT_EQ(got[1], b);
    EXPECT_EQ(asm_.fill(), 0u);
  }
}

TEST(TcpFrame, BadHeadersAreRefusedAsSoonAsTheHeaderIsIn) {
  for (const std::vector<std::uint8_t>& h :
       {std::vector<std::uint8_t>{0, 1, 0, 1, 0, 6, 1},       // protocol id 1
        std::vector<std::uint8_t>{0, 1, 0, 0, 0, 1, 1},       // length 1
        std::vector<std::uint8_t>{0, 1, 0, 0, 0, 255, 1}}) {  // length 255 > 254
    TcpFrameAssembler asm_;
    ASSERT_EQ(asm_.Append(h.data(), 6), 6u);
    EXPECT_EQ(asm_.Next(), FrameState::kNeedMore);
    ASSERT_EQ(asm_.Append(h.data() + 6, 1), 1u);
    EXPECT_EQ(asm_.Next(), FrameState::kBadHeader);
    EXPECT_TRUE(asm_.Pending());
  }
}

TEST(TcpFrame, TheLargestFrameFillsTheBufferExactlyAndNothingMoreIsTaken) {
  std::vector<std::uint8_t> pdu(253, 0);
  pdu[0] = 16;
  const auto f = Frame(7, 1, pdu);
  ASSERT_EQ(f.size(), kMaxTcpAdu);
  TcpFrameAssembler asm_;
  const std::vector<std::uint8_t> more(10, 0);
  ASSERT_EQ(asm_.Append(f.data(), f.size()), kMaxTcpAdu);
  EXPECT_EQ(asm_.space_size(), 0u);
  EXPECT_EQ(asm_.Append(more.data(), more.size()), 0u);
  EXPECT_FALSE(asm_.Commit(1));
  ASSERT_EQ(asm_.Next(), FrameState::kFrame);
  EXPECT_EQ(asm_.frame_length(), kMaxTcpAdu);
  asm_.Pop();
  EXPECT_EQ(asm_.fill(), 0u);
}

}  // namespace
}  // namespace ftstack::fw
