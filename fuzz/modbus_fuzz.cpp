// libFuzzer harness: the Modbus request handler over a real RegisterMap and Device, as the TCP and
// RTU slaves call it (replies go through libmodbus into a socket pair that is drained). The first
// byte picks TCP (MBAP header) or RTU (unit id + CRC) framing and whether a reply is sent.
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

#include "firmware/modbus_server.hpp"
#include "firmware/register_map.hpp"
#include "fuzz/constant_device.hpp"

namespace {

struct Bench {
  Bench() {
    ftstack::fuzz::StartConstantDevice(device);
    if (socketpair(AF_UNIX, SOCK_STREAM, 0, sv) != 0) std::abort();
    tcp = modbus_new_tcp("127.0.0.1", 502);
    rtu = modbus_new_rtu("/dev/null", 19200, 'N', 8, 1);
    mapping =
        modbus_mapping_new(0, 0, ftstack::fw::kHoldingRegisterSpan, ftstack::fw::kInputAddressSpan);
    if (tcp == nullptr || rtu == nullptr || mapping == nullptr) std::abort();
    (void)modbus_set_response_timeout(tcp, 0, 1);
    (void)modbus_set_response_timeout(rtu, 0, 1);
    (void)modbus_set_socket(tcp, sv[0]);
    (void)modbus_set_socket(rtu, sv[0]);
  }
  void Drain() const {
    std::uint8_t buf[1024];
    while (recv(sv[1], buf, sizeof buf, MSG_DONTWAIT) > 0) {
    }
  }
  ftstack::fuzz::ConstantAdc adc;
  ftstack::fw::WrenchCore core;
  ftstack::fw::Device device{adc, core};
  ftstack::fw::RegisterMap map{device};
  int sv[2] = {-1, -1};
  modbus_t* tcp = nullptr;
  modbus_t* rtu = nullptr;
  modbus_mapping_t* mapping = nullptr;
  ftstack::fw::ServerCounters counters;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Bench bench;
  if (size < 2 || size > 1 + 260) return 0;
  const bool rtu = (data[0] & 1) != 0;
  const bool reply = (data[0] & 2) == 0;
  const int header = rtu ? 1 : 7;
  const int length = static_cast<int>(size - 1);
  if (length < header + 1 + (rtu ? 2 : 0)) return 0;  // the servers deliver whole frames only
  (void)ftstack::fw::HandleRequest(bench.map, rtu ? bench.rtu : bench.tcp, bench.mapping, data + 1,
                                   length, header, reply, &bench.counters);
  bench.Drain();
  bool published = false;
  (void)bench.device.Step(&published);  // settings written by the request take effect
  return 0;
}
