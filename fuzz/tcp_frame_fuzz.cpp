// libFuzzer harness: Modbus TCP frame assembly (TcpFrameAssembler) against a reference parse of
// the whole stream. The first byte seeds the read sizes, so one input is delivered in many ways.
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "firmware/tcp_frame.hpp"

namespace {

using ftstack::fw::FrameState;
using ftstack::fw::kMaxTcpAdu;

/// Reference: the frames of a whole stream read at once, up to a refused header.
constexpr std::size_t kMaxInput = 8192;
constexpr std::size_t kMaxFrames = kMaxInput / 8;  // a frame takes at least 8 bytes
struct Reference {
  std::size_t offsets[kMaxFrames];
  std::size_t lengths[kMaxFrames];
  std::size_t count = 0;
  bool refused = false;
};

void Parse(const std::uint8_t* d, std::size_t n, Reference* r) {
  std::size_t at = 0;
  while (n - at >= 7) {
    const unsigned protocol = (d[at + 2] << 8) | d[at + 3];
    const unsigned length = (d[at + 4] << 8) | d[at + 5];
    if (protocol != 0 || length < 2 || length > 254) {
      r->refused = true;
      return;
    }
    if (n - at < 6 + length) return;
    r->offsets[r->count] = at;
    r->lengths[r->count++] = 6 + length;
    at += 6 + length;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1 || size > kMaxInput) return 0;
  std::uint32_t seed = data[0] * 2654435761u + 1;
  const std::uint8_t* d = data + 1;
  const std::size_t n = size - 1;
  static Reference ref;
  ref.count = 0;
  ref.refused = false;
  Parse(d, n, &ref);
  ftstack::fw::TcpFrameAssembler a;
  std::size_t fed = 0;
  std::size_t seen = 0;
  bool refused = false;
  while (!refused) {
    // Serve what is buffered, as the server does.
    FrameState st = a.Next();
    while (st == FrameState::kFrame) {
      if (seen >= ref.count || a.frame_length() != ref.lengths[seen] ||
          a.frame_length() > kMaxTcpAdu ||
          std::memcmp(a.frame(), d + ref.offsets[seen], a.frame_length()) != 0) {
        std::abort();  // a frame the reference does not have, or different bytes
      }
      if (a.unit() != d[ref.offsets[seen] + 6]) std::abort();
      ++seen;
      a.Pop();
      st = a.Next();
    }
    if (st == FrameState::kBadHeader) {
      refused = true;
      break;
    }
    if (a.Pending()) std::abort();  // kNeedMore must not claim a pending frame
    if (fed == n) break;
    if (a.space_size() == 0) std::abort();  // a buffer full without a frame or a refusal
    seed = seed * 1103515245u + 12345u;
    std::size_t chunk = 1 + (seed >> 16) % 300;
    if (chunk > n - fed) chunk = n - fed;
    if (seed & 1) {
      fed += a.Append(d + fed, chunk);
    } else {
      const std::size_t k = chunk < a.space_size() ? chunk : a.space_size();
      std::memcpy(a.space(), d + fed, k);
      if (!a.Commit(k)) std::abort();
      fed += k;
    }
  }
  // Every reference frame delivered, and a refusal exactly where the reference refuses.
  if (seen != ref.count || refused != ref.refused) std::abort();
  if (a.Commit(a.space_size() + 1)) std::abort();
  return 0;
}
