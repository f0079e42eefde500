// libFuzzer harness: ftd's RDT request handler (daemon/rdt_server) — datagrams from up to 16
// client addresses interleaved with published samples, so starts, stops, counts and buffered
// packets meet the client table's bounds. The socket is not opened (sends fail and are counted).
#include <cstddef>
#include <cstdint>

#include "daemon/rdt_server.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static ftstack::daemon::RdtServer* server = [] {
    ftstack::daemon::RdtOptions o;
    o.buffer_records = 3;
    return new ftstack::daemon::RdtServer(o, nullptr);
  }();
  ftstack::fw::DeviceSample d{};
  std::size_t at = 0;
  while (at < size) {
    // Each chunk: 1 byte (client 0…15 and length 0…15), then that many bytes of datagram.
    const std::uint8_t head = data[at++];
    const std::size_t len = head & 0x0F;
    const std::size_t take = len <= size - at ? len : size - at;
    server->HandleRequest(data + at, static_cast<long>(take), 0x0100007Fu, (head >> 4) + 1u);
    at += take;
    d.sample.sequence += 1;
    d.sample.wrench[at % 6] = static_cast<std::int32_t>(head) * 100003;
    server->Publish(d);
    server->DrainRing();
  }
  return 0;
}
