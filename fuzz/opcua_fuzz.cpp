// libFuzzer harness: ftd's OPC UA server as ftd builds it (OpcuaServer over a real RegisterMap and
// Device, serving on its own thread) fed one connection per input. The input goes straight into
// the server's connection callback, the one its TCP layer calls with received bytes, from a
// connection manager that keeps no socket: no kernel round trip per input, so thousands of inputs
// a second. The first byte: bit 0 prepends a valid Hello; bits 1-3 choose the piece size the rest
// arrives in (0: whole; else 2^(n+2) bytes, so a message split across reads is reassembled); bit 4
// gives each message the security token the server issued; the connection is then closed. open62541
// is built for fuzzing (FUZZING_BUILD_MODE_UNSAFE_FOR_ PRODUCTION: no channel id, sequence number
// and session token checks), so a recorded session (fuzz/opcua_seed.mjs) replays past CreateSession
// into the services.
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "daemon/opcua_send_batch.hpp"
#include "daemon/opcua_server.hpp"
#include "fuzz/constant_device.hpp"

namespace {

/// The connection the server last asked to close (it is fed no more).
std::atomic<std::uintptr_t> g_closed{0};

/// The security token the server gave the last channel it opened (its OpenSecureChannel response).
std::atomic<std::uint32_t> g_token{0};

std::uint32_t GetU32(const std::uint8_t* p) {
  return p[0] | (p[1] << 8) | (p[2] << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

/// What the server sends is dropped but for the token of an OpenSecureChannel response: with
/// security None the response ends with the token (channel, token id, created at, lifetime) and
/// an empty server nonce.
UA_StatusCode Discard(UA_ConnectionManager*, std::uintptr_t, const UA_KeyValueMap*,
                      UA_ByteString* buf) {
  if (buf->length >= 40 && std::memcmp(buf->data, "OPNF", 4) == 0 &&
      static_cast<std::int32_t>(GetU32(buf->data + buf->length - 4)) <= 0) {
    g_token = GetU32(buf->data + buf->length - 20);
  }
  UA_ByteString_clear(buf);
  return UA_STATUSCODE_GOOD;
}
UA_StatusCode Close(UA_ConnectionManager*, std::uintptr_t id) {
  g_closed = id;
  return UA_STATUSCODE_GOOD;
}
UA_StatusCode Alloc(UA_ConnectionManager*, std::uintptr_t, UA_ByteString* buf, size_t size) {
  return UA_ByteString_allocBuffer(buf, size);
}
void Free(UA_ConnectionManager*, std::uintptr_t, UA_ByteString* buf) { UA_ByteString_clear(buf); }

struct Bench {
  Bench() {
    ftstack::fuzz::StartConstantDevice(device);
    options.opcua = "127.0.0.1:0";
    ftstack::daemon::OpcuaDeviceInfo info;
    info.rated = {200, 200, 400, 10, 10, 8};
    info.serial = "fuzz";
    info.adc = "constant";
    server = std::make_unique<ftstack::daemon::OpcuaServer>(options, &map, info);
    server->Open();
    thread = std::thread([this] { server->Run(stop); });
    entry = ftstack::daemon::OpcuaServerEntryPoint();
    if (entry.callback == nullptr) std::abort();
    cm.eventSource.eventSourceType = UA_EVENTSOURCETYPE_CONNECTIONMANAGER;
    cm.eventSource.eventLoop = entry.event_loop;
    cm.protocol = UA_STRING(const_cast<char*>("tcp"));
    cm.sendWithConnection = Discard;
    cm.closeConnection = Close;
    cm.allocNetworkBuffer = Alloc;
    cm.freeNetworkBuffer = Free;
    // The server registers a listening socket on its first callback; connections inherit that.
    entry.callback(&cm, 1, entry.application, &listen_context, UA_CONNECTIONSTATE_ESTABLISHED,
                   &UA_KEYVALUEMAP_NULL, UA_BYTESTRING_NULL);
    if (listen_context == nullptr) std::abort();
  }
  ~Bench() {
    // The server's shutdown waits until every socket it knows is closed, the made-up one too.
    entry.callback(&cm, 1, entry.application, &listen_context, UA_CONNECTIONSTATE_CLOSING,
                   &UA_KEYVALUEMAP_NULL, UA_BYTESTRING_NULL);
    stop = true;
    thread.join();
  }
  ftstack::fuzz::ConstantAdc adc;
  ftstack::fw::WrenchCore core;
  ftstack::fw::Device device{adc, core};
  ftstack::fw::RegisterMap map{device};
  ftstack::daemon::FtdOptions options;
  std::unique_ptr<ftstack::daemon::OpcuaServer> server;
  std::atomic<bool> stop{false};
  std::thread thread;
  ftstack::daemon::OpcuaServerEntry entry;
  UA_ConnectionManager cm{};
  void* listen_context = nullptr;
  std::uintptr_t next_id = 2;
};

void PutU32(std::vector<std::uint8_t>* b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// A Hello message (OPC UA Part 6, 7.1.2.3) for the server's endpoint.
std::vector<std::uint8_t> Hello(std::uint16_t port) {
  const std::string url = "opc.tcp://127.0.0.1:" + std::to_string(port);
  std::vector<std::uint8_t> b = {'H', 'E', 'L', 'F'};
  PutU32(&b, static_cast<std::uint32_t>(32 + url.size()));
  PutU32(&b, 0);      // protocol version
  PutU32(&b, 65535);  // receive buffer
  PutU32(&b, 65535);  // send buffer
  PutU32(&b, 0);      // max message size: no limit
  PutU32(&b, 0);      // max chunk count: no limit
  PutU32(&b, static_cast<std::uint32_t>(url.size()));
  b.insert(b.end(), url.begin(), url.end());
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Bench bench;
  if (size < 1 || size > 1 + 65536) return 0;
  std::vector<std::uint8_t> msg;
  if ((data[0] & 1) != 0) msg = Hello(bench.server->port());
  msg.insert(msg.end(), data + 1, data + size);
  const unsigned split = (data[0] >> 1) & 7u;
  const std::size_t piece = split == 0 ? msg.size() : std::size_t{1} << (split + 2);
  const bool renew_token = (data[0] & 16) != 0;
  const std::uintptr_t id = bench.next_id++;
  void* context = bench.listen_context;
  std::size_t at = 0;
  while (at < msg.size() && g_closed != id) {
    // Bit 4: message by message, each MSG and CLO given the token the server issued (a recorded
    // session carries the token of the run it was recorded in).
    std::size_t end = msg.size();
    if (renew_token && msg.size() - at >= 16) {
      std::uint8_t* m = msg.data() + at;
      const std::uint32_t len = GetU32(m + 4);
      if (len >= 16 && len <= msg.size() - at) {
        end = at + len;
        if (std::memcmp(m, "MSG", 3) == 0 || std::memcmp(m, "CLO", 3) == 0) {
          const std::uint32_t t = g_token;
          for (int i = 0; i < 4; ++i) m[12 + i] = static_cast<std::uint8_t>(t >> (8 * i));
        }
      }
    }
    for (; at < end && g_closed != id; at += std::min(piece, end - at)) {
      bench.entry.callback(&bench.cm, id, bench.entry.application, &context,
                           UA_CONNECTIONSTATE_ESTABLISHED, &UA_KEYVALUEMAP_NULL,
                           UA_ByteString{std::min(piece, end - at), msg.data() + at});
    }
    at = end;
  }
  if (msg.empty()) {  // the connection opens and closes without a byte
    bench.entry.callback(&bench.cm, id, bench.entry.application, &context,
                         UA_CONNECTIONSTATE_ESTABLISHED, &UA_KEYVALUEMAP_NULL, UA_BYTESTRING_NULL);
  }
  bench.entry.callback(&bench.cm, id, bench.entry.application, &context, UA_CONNECTIONSTATE_CLOSING,
                       &UA_KEYVALUEMAP_NULL, UA_BYTESTRING_NULL);
  return 0;
}
