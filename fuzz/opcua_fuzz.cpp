// libFuzzer harness: ftd's OPC UA server as ftd wires it (OpcuaServer over a real RegisterMap and
// Device, its own thread, security None on loopback) fed one TCP connection per input. The first
// byte's bit 0 prepends a valid Hello, so that the input reaches the secure channel and the
// service decoding; the rest is sent as it is, the connection half-closed, and the reply read
// until the server closes it (a finding in the server thread is reported on this input).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "daemon/opcua_server.hpp"
#include "fuzz/constant_device.hpp"

namespace {

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
  }
  ~Bench() {
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
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) std::abort();
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(bench.server->port());
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) std::abort();
  const timeval timeout{2, 0};  // the server answers or closes well within this
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  std::size_t sent = 0;
  while (sent < msg.size()) {
    const ssize_t n = send(fd, msg.data() + sent, msg.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server closed on an error early
    sent += static_cast<std::size_t>(n);
  }
  shutdown(fd, SHUT_WR);
  std::uint8_t buf[4096];
  while (recv(fd, buf, sizeof buf, 0) > 0) {
  }
  close(fd);
  return 0;
}
