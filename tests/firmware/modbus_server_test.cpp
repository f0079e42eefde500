// Request decoding under random input: every frame gets a well-formed reply or none, never a crash.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <sys/socket.h>
#include <unistd.h>

#include <random>
#include <vector>

#include "firmware/modbus_server.hpp"
#include "tests/firmware/fake_adc.hpp"

namespace ftstack::fw {
namespace {

TEST(ModbusServerFuzz, RandomTcpRequestsGetWellFormedRepliesAndKeepRegistersValid) {
  test::FakeAdc adc;
  WrenchCore core;
  Device device(adc, core);
  DeviceConfig cfg;
  cfg.adc.channel_count = 6;
  FloatCalibration fc;
  fc.channel_count = 6;
  for (std::size_t i = 0; i < 6; ++i) fc.matrix[i][i] = 100.0;
  hal::AdcInfo info{6, -(1 << 23), (1 << 23) - 1, 3906250, 1000, false};
  ASSERT_EQ(LoadCalibration(fc, info, &cfg.slots[0].fixed, nullptr), LoadStatus::kOk);
  cfg.slots[0].present = true;
  ASSERT_EQ(device.Start(cfg), DeviceStatus::kOk);
  RegisterMap map(device);

  int sv[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_STREAM, 0, sv), 0);
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", 502);
  modbus_mapping_t* mapping = modbus_mapping_new(0, 0, kHoldingRegisterSpan, kInputRegisterCount);
  modbus_set_socket(ctx, sv[0]);
  std::mt19937 rng(2024);
  ServerCounters counters;
  int normal = 0, exceptions = 0, dropped = 0;
  for (int i = 0; i < 100000; ++i) {
    // A valid MBAP header (unit 1) and a PDU of random length and content; a third of the time
    // the function code is one the map serves, so decoding goes deep.
    const std::size_t pdu = 1 + rng() % 253;
    std::vector<std::uint8_t> f = {0x12,
                                   0x34,
                                   0x00,
                                   0x00,
                                   static_cast<std::uint8_t>((pdu + 1) >> 8),
                                   static_cast<std::uint8_t>(pdu + 1),
                                   0x01};
    for (std::size_t k = 0; k < pdu; ++k) f.push_back(static_cast<std::uint8_t>(rng()));
    const std::uint8_t served[] = {0x03, 0x04, 0x06, 0x10};
    if (i % 3 == 0) f[7] = served[rng() % 4];
    if (i % 6 == 0) {  // a plausible request: small address, count and values
      const std::uint8_t code = served[rng() % 4];
      const std::uint8_t addr = static_cast<std::uint8_t>(rng() % 80);
      const std::uint8_t count = static_cast<std::uint8_t>(1 + rng() % 6);
      f.resize(7);
      f.insert(f.end(), {code, 0, addr});
      if (code == 0x06) {
        f.insert(f.end(), {0, static_cast<std::uint8_t>(rng() % 300)});
      } else {
        f.insert(f.end(), {0, count});
      }
      if (code == 0x10) {
        f.push_back(static_cast<std::uint8_t>(2 * count));
        for (int k = 0; k < count; ++k) {
          f.insert(f.end(), {0, static_cast<std::uint8_t>(rng() % 300)});
        }
      }
      f[4] = 0;
      f[5] = static_cast<std::uint8_t>(f.size() - 6);
    }
    const std::uint8_t function = f[7];
    ASSERT_TRUE(
        HandleRequest(map, ctx, mapping, f.data(), static_cast<int>(f.size()), 7, true, &counters));
    std::uint8_t rsp[300];
    const ssize_t n = recv(sv[1], rsp, sizeof(rsp), MSG_DONTWAIT);
    if (function >= 0x80) {  // not a request: dropped without reply
      EXPECT_EQ(n, -1) << "request " << i;
      ++dropped;
      continue;
    }
    ASSERT_GE(n, 9) << "request " << i;
    EXPECT_EQ(rsp[0], 0x12);
    EXPECT_EQ(rsp[1], 0x34);
    EXPECT_EQ((rsp[4] << 8) | rsp[5], n - 6);  // MBAP length matches what was sent
    if (rsp[7] == (function | 0x80)) {
      EXPECT_TRUE(rsp[8] >= 1 && rsp[8] <= 3) << "exception " << static_cast<int>(rsp[8]);
      ++exceptions;
    } else {
      EXPECT_EQ(rsp[7], function);
      ++normal;
    }
  }
  EXPECT_GT(normal, 100);
  EXPECT_GT(exceptions, 10000);
  EXPECT_GT(dropped, 1000);
  EXPECT_EQ(counters.dropped.load(), static_cast<std::uint64_t>(dropped));
  // Whatever was written, the holding registers hold valid values.
  std::uint16_t h[5];
  ASSERT_EQ(map.ReadHolding(0, 5, h), ModbusException::kNone);
  EXPECT_EQ(h[kHoldCommand], 0);
  EXPECT_TRUE(h[kHoldFilterLength] >= 1 && h[kHoldFilterLength] <= 256);
  EXPECT_TRUE(h[kHoldDecimation] >= 1 && h[kHoldDecimation] <= 1000);
  EXPECT_EQ(h[kHoldCalSlot], 0);
  bool published = false;
  EXPECT_EQ(device.Step(&published), hal::Status::kOk);  // the device still applies its settings
  modbus_set_socket(ctx, -1);
  modbus_free(ctx);
  modbus_mapping_free(mapping);
  close(sv[0]);
  close(sv[1]);
}

}  // namespace
}  // namespace ftstack::fw
