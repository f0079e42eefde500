// End to end: simulated wrench → ftd (real binary) → Modbus TCP → libmodbus client in this process.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <system_error>
#include <thread>

#include "calibration/file/cal_file.hpp"
#include "firmware/modbus_server.hpp"
#include "firmware/register_map.hpp"
#include "measurement/recording.hpp"
#include "sim/default_sensor.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/sensor_description.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/builtin_adc.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/raw_connect.hpp"
#include "tests/system/sim_noise.hpp"

namespace ftstack {
namespace {

using fw::UnpackFloat32;
using fw::UnpackI32;
using fw::UnpackU32;

/// Per-axis noise of one sample of the built-in simulated sensor, derived by propagating the
/// simulated ADC's input noise and its quantisation (uniform, q²/12) through the calibration
/// matrix; and the fixed-point core's worst-case error bound.
struct Expected {
  std::array<double, 6> sigma_si{};
  std::array<double, 6> fixed_error_si{};
};
Expected DeriveExpected() {
  const test::SimNoise n = test::DeriveSimNoise();
  return {n.sigma, n.fixed_error};
}

/// A libmodbus TCP client connected to the daemon.
class Client {
 public:
  explicit Client(int port, int unit = 1, double timeout_s = 1.0) {
    ctx_ = modbus_new_tcp("127.0.0.1", port);
    modbus_set_slave(ctx_, unit);
    const auto us = static_cast<std::uint32_t>(timeout_s * 1e6);
    modbus_set_response_timeout(ctx_, us / 1000000, us % 1000000);
    connected_ = modbus_connect(ctx_) == 0;
  }
  ~Client() {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  [[nodiscard]] bool connected() const { return connected_; }
  modbus_t* ctx() { return ctx_; }
  /// Reads input registers; returns the libmodbus result (count or -1) and errno in *err.
  int Input(int addr, int count, std::uint16_t* out, int* err = nullptr) {
    const int rc = modbus_read_input_registers(ctx_, addr, count, out);
    if (err != nullptr) *err = rc < 0 ? errno : 0;
    return rc;
  }
  int Holding(int addr, int count, std::uint16_t* out, int* err = nullptr) {
    const int rc = modbus_read_registers(ctx_, addr, count, out);
    if (err != nullptr) *err = rc < 0 ? errno : 0;
    return rc;
  }
  int Write(int addr, std::uint16_t v, int* err = nullptr) {
    const int rc = modbus_write_register(ctx_, addr, v);
    if (err != nullptr) *err = rc < 0 ? errno : 0;
    return rc;
  }
  int WriteMany(int addr, const std::vector<std::uint16_t>& v, int* err = nullptr) {
    const int rc = modbus_write_registers(ctx_, addr, static_cast<int>(v.size()), v.data());
    if (err != nullptr) *err = rc < 0 ? errno : 0;
    return rc;
  }
  std::uint32_t Sequence() {
    std::uint16_t r[2] = {0, 0};
    if (Input(fw::kInSequence, 2, r) != 2) return 0;
    return UnpackU32(r);
  }
  /// Waits until `n` more samples have been published (up to 10 s).
  bool WaitSamples(std::uint32_t n) {
    const std::uint32_t start = Sequence();
    for (int i = 0; i < 1000; ++i) {
      if (Sequence() - start >= n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

 private:
  modbus_t* ctx_ = nullptr;
  bool connected_ = false;
};

constexpr double kSigmas = 5.0;  // 5σ: a false failure once in ~1.7 million axis checks

TEST(FtdModbus, SimulatedWrenchArrivesWithinDerivedToleranceAndTareZeroes) {
  const std::array<double, 6> applied = {20.0, -10.0, -150.0, 0.5, -0.3, 0.2};
  test::FtdProcess ftd({"--adc", "sim", "--sim-wrench", "20,-10,-150,0.5,-0.3,0.2", "--rate-hz",
                        "1000", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  Client c(ftd.port());
  ASSERT_TRUE(c.connected());
  const Expected e = DeriveExpected();
  constexpr int kFilter = 256;
  ASSERT_EQ(c.Write(fw::kHoldFilterLength, kFilter), 1);
  std::uint16_t h = 0;
  ASSERT_EQ(c.Holding(fw::kHoldFilterLength, 1, &h), 1);
  EXPECT_EQ(h, kFilter);
  ASSERT_TRUE(c.WaitSamples(kFilter + 20));

  std::array<std::uint16_t, 30> r{};
  ASSERT_EQ(c.Input(0, 30, r.data()), 30);
  EXPECT_EQ(r[fw::kInMapVersion], 3);  // docs/spec/modbus-map.md
  EXPECT_EQ(r[fw::kInStatus] & ~fw::kStatusStale, fw::kStatusSimulated);
  for (std::size_t a = 0; a < 6; ++a) {
    const double tol = kSigmas * e.sigma_si[a] / std::sqrt(kFilter) + e.fixed_error_si[a] +
                       std::fabs(applied[a]) * 6e-8;
    const double got = UnpackFloat32(&r[fw::kInWrenchFloat + 2 * a]);
    EXPECT_NEAR(got, applied[a], tol) << "axis " << a;
    // int32 registers: mN and mN·m of the same sample.
    EXPECT_NEAR(UnpackI32(&r[fw::kInWrenchInt + 2 * a]), got * 1e3,
                0.5 + std::fabs(got) * 1e3 * 6e-8)
        << "axis " << a;
  }
  // Unit 255 is answered over TCP as well.
  Client wildcard(ftd.port(), 255);
  ASSERT_TRUE(wildcard.connected());
  EXPECT_EQ(wildcard.Input(0, 1, r.data()), 1);

  // Tare: the tare averages rate/10 = 100 samples; afterwards the filtered reading is the
  // difference of two independent averages.
  ASSERT_EQ(c.Write(fw::kHoldCommand, fw::kCmdTare), 1);
  ASSERT_EQ(c.Holding(fw::kHoldCommand, 1, &h), 1);
  EXPECT_EQ(h, 0);  // the command register reads 0
  bool tared = false;
  for (int i = 0; i < 500 && !tared; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_EQ(c.Input(fw::kInStatus, 1, &h), 1);
    tared = (h & fw::kStatusTareActive) != 0;
  }
  ASSERT_TRUE(tared);
  ASSERT_TRUE(c.WaitSamples(kFilter + 20));
  ASSERT_EQ(c.Input(0, 30, r.data()), 30);
  for (std::size_t a = 0; a < 6; ++a) {
    const double tol =
        kSigmas * e.sigma_si[a] * std::sqrt(1.0 / kFilter + 1.0 / 100.0) + 2.0 * fw::AxisLsb(a);
    EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 2 * a]), 0.0, tol) << "axis " << a;
  }
  EXPECT_EQ(ftd.Stop(SIGTERM), 0);
}

TEST(FtdModbus, ExceptionsAndProtectedWritesOverTheWire) {
  test::FtdProcess ftd({"--modbus-tcp", "127.0.0.1:0", "--unit-id", "7"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  Client c(ftd.port(), 7);
  ASSERT_TRUE(c.connected());
  std::array<std::uint16_t, 130> r{};
  int err = 0;
  EXPECT_EQ(c.Input(fw::kInputAddressSpan, 1, r.data(), &err), -1);
  EXPECT_EQ(err, EMBXILADD);
  EXPECT_EQ(c.Input(fw::kInputAddressSpan - 4, 5, r.data(), &err), -1);
  EXPECT_EQ(err, EMBXILADD);
  EXPECT_EQ(c.Holding(fw::kHoldingRegisterSpan, 1, r.data(), &err), -1);  // map v2: 0 … 41
  EXPECT_EQ(err, EMBXILADD);
  EXPECT_EQ(c.Write(fw::kHoldingRegisterSpan, 0, &err), -1);
  EXPECT_EQ(err, EMBXILADD);
  // Reserved 5 … 9: read 0, accept only 0.
  EXPECT_EQ(c.Holding(5, 5, r.data(), &err), 5);
  EXPECT_EQ(c.Write(9, 1, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  EXPECT_EQ(c.Write(9, 0, &err), 1);
  // Unknown function (read coils) → 01.
  std::uint8_t bits[8];
  EXPECT_EQ(modbus_read_bits(c.ctx(), 0, 1, bits), -1);
  EXPECT_EQ(errno, EMBXILFUN);
  // Protected writes while locked → 03 and nothing changes.
  EXPECT_EQ(c.Write(fw::kHoldCalSlot, 1, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  std::vector<std::uint16_t> d(4);
  fw::PackFloat32(0.05f, &d[0]);
  fw::PackFloat32(0.10f, &d[2]);
  EXPECT_EQ(c.WriteMany(fw::kHoldTransform, d, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  ASSERT_EQ(c.Holding(0, 5, r.data()), 5);
  EXPECT_EQ(r[fw::kHoldCalSlot], 0);
  EXPECT_EQ(r[fw::kHoldUnlock], 0);
  ASSERT_EQ(c.Holding(fw::kHoldTransform, 12, r.data()), 12);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(r[i], 0) << i;
  // Out-of-range values → 03.
  EXPECT_EQ(c.Write(fw::kHoldFilterLength, 0, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  EXPECT_EQ(c.Write(fw::kHoldCommand, 9, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  // Unlock, then the transform is accepted and reads back.
  ASSERT_EQ(c.Write(fw::kHoldUnlock, fw::kUnlockKey), 1);
  ASSERT_EQ(c.Holding(fw::kHoldUnlock, 1, r.data()), 1);
  EXPECT_EQ(r[0], 1);
  ASSERT_EQ(c.WriteMany(fw::kHoldTransform, d), 4);
  ASSERT_EQ(c.Holding(fw::kHoldTransform, 4, r.data()), 4);
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[0]), 0.05f);
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[2]), 0.10f);
  // The slot register: only slot 0 exists without --cal-b.
  EXPECT_EQ(c.Write(fw::kHoldCalSlot, 1, &err), -1);
  EXPECT_EQ(err, EMBXILVAL);
  // A unit id that is neither ours nor 255 gets no answer.
  Client other(ftd.port(), 1, 0.3);
  ASSERT_TRUE(other.connected());
  EXPECT_EQ(other.Input(0, 1, r.data(), &err), -1);
  EXPECT_EQ(err, ETIMEDOUT);
  EXPECT_EQ(ftd.Stop(SIGINT), 0);
}

TEST(FtdModbus, OverloadPeaksAndToolTransformEndToEnd) {
  // Fz = 450 N on a 400 N axis (112 %): overloaded. 10 N along x acting 0.1 m above the sensor
  // origin shows as My = +1 N·m at the sensor and as no moment at that tool point.
  test::FtdProcess ftd(
      {"--sim-wrench", "10,0,450,0,1,0", "--rate-hz", "1000", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  Client c(ftd.port());
  ASSERT_TRUE(c.connected());
  const Expected e = DeriveExpected();
  ASSERT_TRUE(c.WaitSamples(200));
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  EXPECT_NE(r[fw::kInStatus] & fw::kStatusOverload, 0);
  // One continuing overload is one event, not one per sample.
  EXPECT_EQ(UnpackU32(&r[fw::kInOverloadEvents]), 1u);
  // The peak is the largest |Fz| of ~200+ unfiltered samples: above the load, and not by more
  // than the extreme of that many normal draws (≤ 5σ).
  const double peak = UnpackFloat32(&r[fw::kInPeaks + 4]);
  EXPECT_GT(peak, 450.0 - e.fixed_error_si[2]);
  EXPECT_LT(peak, 450.0 + kSigmas * e.sigma_si[2] + e.fixed_error_si[2]);
  // Clearing while the overload continues: the counter restarts at the ongoing event.
  ASSERT_EQ(c.Write(fw::kHoldCommand, fw::kCmdClearPeaks), 1);
  ASSERT_TRUE(c.WaitSamples(5));
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  EXPECT_EQ(UnpackU32(&r[fw::kInOverloadEvents]), 1u);
  EXPECT_LT(UnpackFloat32(&r[fw::kInPeaks + 4]),
            450.0 + kSigmas * e.sigma_si[2] + e.fixed_error_si[2]);

  // Tool transform: unlock, D = (0, 0, 0.1) m.
  ASSERT_EQ(c.Write(fw::kHoldFilterLength, 256), 1);
  ASSERT_EQ(c.Write(fw::kHoldUnlock, fw::kUnlockKey), 1);
  std::vector<std::uint16_t> d(6);
  fw::PackFloat32(0.0f, &d[0]);
  fw::PackFloat32(0.0f, &d[2]);
  fw::PackFloat32(0.1f, &d[4]);
  ASSERT_EQ(c.WriteMany(fw::kHoldTransform, d), 6);
  ASSERT_TRUE(c.WaitSamples(300));
  ASSERT_EQ(c.Input(0, 30, r.data()), 30);
  // My_tool = My − (D × F)_y = My − Dz·Fx: its noise is that of My and 0.1 × that of Fx.
  const double sigma_my = std::hypot(e.sigma_si[4], 0.1 * e.sigma_si[0]) / std::sqrt(256.0);
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 8]), 0.0,
              kSigmas * sigma_my + e.fixed_error_si[4] + 0.1 * e.fixed_error_si[0] + 1e-5);
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat]), 10.0,
              kSigmas * e.sigma_si[0] / 16.0 + e.fixed_error_si[0] + 1e-5);
  // Peaks stay in the sensor frame: the peak My is the sensor's 1 N·m.
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInPeaks + 8]), 1.0,
              kSigmas * e.sigma_si[4] + e.fixed_error_si[4]);
  EXPECT_EQ(ftd.Stop(), 0);
}

/// Bitwise CRC-32 (IEEE 802.3, reflected), written here independently of cal::Crc32.
std::uint32_t BitwiseCrc32(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const std::uint8_t b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

std::uint32_t FileCrcField(const std::string& path) {
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  return static_cast<std::uint32_t>(std::stoul(j.at("crc32").get<std::string>(), nullptr, 16));
}

TEST(FtdModbus, CalibrationSlotsAndTheirCrc) {
  const auto model = sim::MakeDefaultSensor();
  const test::BuiltinAdc builtin = test::BuiltinSimAdc();
  const hal::AdcInfo adc = builtin.info;
  // Built-in calibration: registers 72–73 hold the CRC-32 of the documented fixed-point layout.
  {
    const fw::FixedCalibration fixed = cal::ToFixed(sim::IdealCalibration(*model, adc), adc);
    std::vector<std::uint8_t> bytes;
    auto le = [&](std::uint64_t v, int n) {
      for (int i = 0; i < n; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    };
    le(fixed.channel_count, 1);
    for (std::size_t r = 0; r < 6; ++r) {
      for (std::size_t ch = 0; ch < fixed.channel_count; ++ch) {
        le(static_cast<std::uint64_t>(fixed.coef[r][ch]), 8);
      }
      le(static_cast<std::uint64_t>(fixed.bias[r]), 8);
      le(fixed.shift[r], 1);
    }
    le(static_cast<std::uint32_t>(fixed.min_counts), 4);
    le(static_cast<std::uint32_t>(fixed.max_counts), 4);
    test::FtdProcess ftd({"--modbus-tcp", "127.0.0.1:0"});
    ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
    Client c(ftd.port());
    std::uint16_t r[2];
    ASSERT_EQ(c.Input(fw::kInCalCrc, 2, r), 2);
    EXPECT_EQ(UnpackU32(r), BitwiseCrc32(bytes));
    EXPECT_EQ(ftd.Stop(), 0);
  }
  // Two files: slot 0 the ideal calibration, slot 1 the same with a doubled matrix.
  char dir[] = "/tmp/ftd_cal_XXXXXX";
  const std::string base = mkdtemp(dir);
  const std::string a = base + "/a.json", b = base + "/b.json";
  cal::CalFile fa = sim::IdealCalibration(*model, adc);
  cal::SaveCalFile(a, fa);
  cal::CalFile fb = fa;
  for (auto& row : fb.cal.matrix) {
    for (double& m : row) m *= 2.0;
  }
  fb.serial = "slot-b";
  cal::SaveCalFile(b, fb);
  test::FtdProcess ftd(
      {"--sim-wrench", "0,0,100,0,0,0", "--cal", a, "--cal-b", b, "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  Client c(ftd.port());
  const Expected e = DeriveExpected();
  ASSERT_EQ(c.Write(fw::kHoldFilterLength, 256), 1);
  ASSERT_TRUE(c.WaitSamples(300));
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  EXPECT_EQ(r[fw::kInCalSlot], 0);
  EXPECT_EQ(UnpackU32(&r[fw::kInCalCrc]), FileCrcField(a));
  const double tol = kSigmas * e.sigma_si[2] / 16.0 + e.fixed_error_si[2];
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 4]), 100.0, tol);
  ASSERT_EQ(c.Write(fw::kHoldUnlock, fw::kUnlockKey), 1);
  ASSERT_EQ(c.Write(fw::kHoldCalSlot, 1), 1);
  ASSERT_TRUE(c.WaitSamples(300));  // the switch restarts the filter
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  EXPECT_EQ(r[fw::kInCalSlot], 1);
  EXPECT_EQ(UnpackU32(&r[fw::kInCalCrc]), FileCrcField(b));
  EXPECT_NE(FileCrcField(a), FileCrcField(b));
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 4]), 200.0, 2 * tol + e.fixed_error_si[2]);
  EXPECT_EQ(ftd.Stop(), 0);
  std::remove(a.c_str());
  std::remove(b.c_str());
  rmdir(base.c_str());
}

using test::RawConnect;

TEST(FtdModbus, GarbageAndHalfFramesDoNotDisturbOtherClients) {
  test::FtdProcess ftd({"--modbus-tcp", "127.0.0.1:0", "--rate-hz", "2000"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  std::atomic<bool> stop{false};
  std::atomic<int> ok{0}, failed{0};
  // A well-behaved client polling the wrench all along (1 s timeout per request).
  std::thread good([&] {
    Client c(ftd.port());
    std::array<std::uint16_t, 74> r{};
    while (!stop) {
      if (c.Input(0, 74, r.data()) == 74 && r[0] == fw::kMapVersion) {
        ++ok;
      } else {
        if (failed++ == 0) {
          std::fprintf(stderr, "first failure: %s after %d ok\n", modbus_strerror(errno),
                       ok.load());
        }
      }
    }
  });
  for (int i = 0; i < 500 && ok == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (ok == 0) {
    stop = true;
    good.join();
    FAIL() << "the polling client never got an answer";
  }
  std::mt19937 rng(42);
  // 1: clients that send half an MBAP header and then go silent (keeping their sockets open),
  // more of them than the server has connection slots.
  std::vector<int> stalled;
  for (std::size_t i = 0; i < fw::kMaxTcpClients + 8; ++i) {
    stalled.push_back(RawConnect(ftd.port()));
    const std::uint8_t half[] = {0x00, 0x01, 0x00};
    (void)send(stalled.back(), half, sizeof(half), MSG_NOSIGNAL);
  }
  // 2: a client that sends half a request and disconnects mid-frame.
  for (int i = 0; i < 20; ++i) {
    const int fd = RawConnect(ftd.port());
    const std::uint8_t part[] = {0x00, 0x02, 0x00, 0x00, 0x00, 0x06, 0x01, 0x04, 0x00};
    EXPECT_EQ(send(fd, part, sizeof(part), MSG_NOSIGNAL), static_cast<ssize_t>(sizeof(part)));
    close(fd);
  }
  // 3: pure garbage streams.
  for (int i = 0; i < 20; ++i) {
    const int fd = RawConnect(ftd.port());
    std::vector<std::uint8_t> junk(1 + rng() % 600);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    (void)send(fd, junk.data(), junk.size(), MSG_NOSIGNAL);
    close(fd);
  }
  // 4: well-framed MBAP with random PDUs (fuzz-like): each gets a reply or is ignored, and the
  // connection stays usable as long as the header is valid.
  const int fuzz = RawConnect(ftd.port());
  EXPECT_GE(fuzz, 0);
  // Without a reply to a dropped frame, Nagle would hold the next frame for the server's
  // delayed ACK (40 ms each).
  const int one = 1;
  setsockopt(fuzz, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  int replies = 0, dropped = 0;
  for (int i = 0; i < 300; ++i) {
    const std::size_t pdu = 1 + rng() % 20;
    std::vector<std::uint8_t> f = {0x12, 0x34, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(pdu + 1),
                                   0x01};
    for (std::size_t k = 0; k < pdu; ++k) f.push_back(static_cast<std::uint8_t>(rng()));
    if (i % 3 == 0) f[7] = static_cast<std::uint8_t>(1 + rng() % 24);  // often a known-ish code
    if (send(fuzz, f.data(), f.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(f.size())) break;
    if ((f[7] & 0x80) != 0) {  // an exception-range code is not a request: dropped, no reply
      ++dropped;
      continue;
    }
    std::uint8_t rsp[300];
    timeval tv{1, 0};
    setsockopt(fuzz, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    const ssize_t n = recv(fuzz, rsp, sizeof(rsp), 0);
    EXPECT_GT(n, 8) << "frame " << i << ": no reply ("
                    << (n < 0 ? std::system_category().message(errno) : std::string("closed"))
                    << ")";
    if (n <= 8) break;
    EXPECT_EQ(rsp[0], 0x12);  // transaction id echoed
    EXPECT_EQ(rsp[1], 0x34);
    ++replies;
  }
  EXPECT_EQ(replies + dropped, 300);
  EXPECT_GT(dropped, 0);
  EXPECT_GT(replies, 150);  // about a third of the codes are in the exception range
  close(fuzz);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  stop = true;
  good.join();
  for (const int fd : stalled) close(fd);
  EXPECT_EQ(failed.load(), 0);
  EXPECT_GT(ok.load(), 50);
  EXPECT_TRUE(ftd.alive());
  EXPECT_EQ(ftd.Stop(SIGTERM), 0);
}

TEST(FtdModbus, PipelinedRequestsInOneSegmentAreAllAnswered) {
  // 40 requests written at once (more than the server serves per connection per poll round, and
  // more than its 260-byte frame buffer holds): every one is answered, in order.
  test::FtdProcess ftd({"--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  const int fd = RawConnect(ftd.port());
  ASSERT_GE(fd, 0);
  std::vector<std::uint8_t> burst;
  constexpr int kRequests = 40;
  for (int t = 0; t < kRequests; ++t) {
    // Read 2 input registers from address 0, transaction id t.
    const std::uint8_t req[] = {0, static_cast<std::uint8_t>(t), 0, 0, 0, 6, 1, 4, 0, 0, 0, 2};
    burst.insert(burst.end(), std::begin(req), std::end(req));
  }
  ASSERT_EQ(send(fd, burst.data(), burst.size(), MSG_NOSIGNAL), static_cast<ssize_t>(burst.size()));
  timeval tv{2, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  constexpr std::size_t kReply = 7 + 2 + 4;  // MBAP, function + byte count, two registers
  std::vector<std::uint8_t> got;
  while (got.size() < kRequests * kReply) {
    std::uint8_t buf[512];
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    got.insert(got.end(), buf, buf + n);
  }
  ASSERT_EQ(got.size(), kRequests * kReply);
  for (int t = 0; t < kRequests; ++t) {
    const std::uint8_t* r = &got[static_cast<std::size_t>(t) * kReply];
    EXPECT_EQ(r[1], t);
    EXPECT_EQ(r[7], 4);
    EXPECT_EQ((r[9] << 8) | r[10], 3);  // map version
  }
  close(fd);
  EXPECT_EQ(ftd.Stop(), 0);
}

/// Triangle wave of Fz through keyframes every 0.5 s: ±300 N, 600 N/s.
double TriangleFz(double t) {
  const double phase = std::fmod(t, 2.0);
  return phase < 1.0 ? -300.0 + 600.0 * phase : 300.0 - 600.0 * (phase - 1.0);
}

TEST(FtdModbus, EveryReplyComesFromOneSample) {
  // Replay a fast ramp: one sample step is 0.6 N of Fz, far above the noise, so a reply mixing
  // the sequence/timestamp of one sample with the wrench of another cannot pass.
  char path[] = "/tmp/ftd_ramp_XXXXXX.csv";
  close(mkstemps(path, 4));
  Recording rec;
  std::vector<double> t, fz, zero;
  for (int i = 0; i <= 40; ++i) {
    t.push_back(i * 0.5);
    fz.push_back(TriangleFz(i * 0.5));
    zero.push_back(0.0);
  }
  rec.SetColumn("t", t);
  for (const std::string& n : WrenchColumns()) rec.SetColumn(n, n == "Fz" ? fz : zero);
  WriteRecording(path, rec);
  test::FtdProcess ftd({"--replay", path, "--rate-hz", "1000", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  const Expected e = DeriveExpected();
  const double tol = kSigmas * e.sigma_si[2] + e.fixed_error_si[2] + 300 * 6e-8;
  ASSERT_LT(tol, 0.3);  // half a sample step: the test can tell neighbouring samples apart
  std::atomic<int> bad{0};
  {
    Client c(ftd.port());
    ASSERT_TRUE(c.WaitSamples(200));  // past start-up, when the sampler may catch up in a burst
  }
  // The timestamp is the measured read time (not count × period), so it cannot be predicted
  // from the sequence: every reply of one sequence number must carry the same timestamp (shared
  // by both readers), and a later sequence a later timestamp. The wrench is the simulator's at
  // the sample's own time (sequence − 1) ms.
  std::mutex seen_mutex;
  std::map<std::uint32_t, std::uint32_t> ts_of_seq;
  auto reader = [&] {
    Client c(ftd.port());
    std::array<std::uint16_t, 18> r{};
    std::uint32_t first = 0;
    std::uint32_t prev_seq = 0;
    std::uint32_t prev_ts = 0;
    // At least one second of samples (1000 sequence numbers) and at least 1000 replies, read as
    // fast as the server answers (on a quiet machine several per sample period; a loaded one
    // reads longer instead of checking fewer replies).
    int replies = 0;
    for (std::uint32_t seq = 0; first == 0 || seq - first < 1000 || replies < 1000;) {
      if (c.Input(0, 18, r.data()) != 18) {
        ++bad;
        continue;
      }
      seq = UnpackU32(&r[fw::kInSequence]);
      const std::uint32_t ts = UnpackU32(&r[fw::kInTimestampUs]);
      if (first == 0) first = seq;
      const double t_s = (seq - 1) * 1e-3;
      bool same = std::fabs(UnpackFloat32(&r[fw::kInWrenchFloat + 4]) - TriangleFz(t_s)) <= tol;
      if (prev_seq != 0) {
        same = same && (seq == prev_seq ? ts == prev_ts : (seq > prev_seq && ts > prev_ts));
      }
      {
        const std::lock_guard<std::mutex> lock(seen_mutex);
        const auto [it, inserted] = ts_of_seq.emplace(seq, ts);
        same = same && (inserted || it->second == ts);
      }
      prev_seq = seq;
      prev_ts = ts;
      if (!same) ++bad;
      ++replies;
    }
  };
  std::thread r1(reader), r2(reader);
  r1.join();
  r2.join();
  EXPECT_EQ(bad.load(), 0);
  EXPECT_EQ(ftd.Stop(), 0);
  std::remove(path);
}

TEST(FtdModbus, LogWritesTheRecordingFormatAndDurationEndsCleanly) {
  char path[] = "/tmp/ftd_log_XXXXXX.csv";
  close(mkstemps(path, 4));
  const auto spawned = std::chrono::steady_clock::now();
  test::FtdProcess ftd(
      {"--sim-wrench", "0,0,-100,0,0,0", "--rate-hz", "1000", "--duration-s", "1", "--log", path},
      false);
  ASSERT_EQ(ftd.Wait(20.0), 0) << ftd.Stderr();
  const double life_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - spawned).count();
  ReadOptions ro;
  ro.required = {"t", "status", "temp_C", "raw0", "raw5"};
  ro.require_bridges = true;
  ro.require_wrench = true;
  const Recording rec = ReadRecording(path, ro);
  // What ftd promises, not how fast a loaded machine stops it: one row per sample with its
  // conversion time (the first at 0, then one period apart: no row lost), and no sample
  // converted after the process ended; the lower bound only checks that it ran about 1 s.
  EXPECT_GE(rec.rows(), 900u);
  const std::vector<double>& t = rec.Column("t");
  ASSERT_FALSE(t.empty());
  EXPECT_NEAR(t.front(), 0.0, 1e-9);
  for (std::size_t k = 1; k < t.size(); ++k) ASSERT_NEAR(t[k] - t[k - 1], 0.001, 1e-7) << k;
  EXPECT_LE(t.back(), life_s);
  EXPECT_EQ(rec.BridgeCount(), 6u);
  const Expected e = DeriveExpected();
  double sum = 0;
  for (double v : rec.Column("Fz")) sum += v;
  const double n = static_cast<double>(rec.rows());
  EXPECT_NEAR(sum / n, -100.0, kSigmas * e.sigma_si[2] / std::sqrt(n) + e.fixed_error_si[2]);
  const test::BuiltinAdc builtin = test::BuiltinSimAdc();
  const hal::AdcInfo adc = builtin.info;
  const double mvv_per_count = adc.full_scale_nvv * 1e-6 / adc.max_counts;
  for (std::size_t i = 0; i < rec.rows(); i += 97) {
    EXPECT_NEAR(rec.Column("b2")[i], rec.Column("raw2")[i] * mvv_per_count, 1e-9);
    EXPECT_EQ(static_cast<int>(rec.Column("status")[i]) & fw::kStatusSimulated,
              fw::kStatusSimulated);
    EXPECT_DOUBLE_EQ(rec.Column("temp_C")[i], 20.0);
  }
  std::remove(path);
}

/// Issue 17, from outside: a tool of 380 N tared, then 460 N on a 400 N sensor. The reader sees
/// 80 N; the overload bit, the event counter and the peak see the 460 N the body carries.
TEST(FtdModbus, OverloadUnderTareSeesTheLoadOnTheBody) {
  const test::TempDir tmp("ftd_tare");
  const std::string path = tmp / "tool.csv";
  Recording rec;
  // The 380 N hold lasts 8 s: the tare and its check (at 1 s and 2.5 s) keep 5.5 s of slack on a
  // loaded machine, where a client's read can come long after the sequence it waited for.
  rec.SetColumn("t", {0.0, 8.0, 8.2, 30.0});
  for (const std::string& n : WrenchColumns()) {
    rec.SetColumn(n, n == "Fz" ? std::vector<double>{380.0, 380.0, 460.0, 460.0}
                               : std::vector<double>(4, 0.0));
  }
  WriteRecording(path, rec);
  test::FtdProcess ftd({"--replay", path, "--rate-hz", "1000", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  Client c(ftd.port());
  auto sequence = [&] {
    std::array<std::uint16_t, 2> r{};
    return c.Input(fw::kInSequence, 2, r.data()) == 2 ? UnpackU32(r.data()) : 0u;
  };
  auto wait_sample = [&](std::uint32_t n) {
    for (int i = 0; i < 20000 && sequence() < n; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return sequence() >= n;
  };
  ASSERT_TRUE(wait_sample(1000));  // 1 s into the 380 N hold
  // A PLC's block read of the holding registers 0 … 15 (5 … 9 reserved) works.
  std::array<std::uint16_t, 16> hold{};
  ASSERT_EQ(c.Holding(0, 16, hold.data()), 16);
  for (int a = 5; a < 10; ++a) EXPECT_EQ(hold[static_cast<std::size_t>(a)], 0) << a;
  ASSERT_EQ(c.Write(fw::kHoldCommand, fw::kCmdTare), 1);
  ASSERT_TRUE(wait_sample(2500));
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  ASSERT_NE(r[fw::kInStatus] & fw::kStatusTareActive, 0);
  ASSERT_LT(UnpackU32(&r[fw::kInTimestampUs]), 8000000u) << "the read came after the 380 N hold";
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 4]), 0.0, 1.0);
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusOverload, 0);  // 95 % of rated
  EXPECT_EQ(UnpackU32(&r[fw::kInOverloadEvents]), 0u);
  ASSERT_TRUE(wait_sample(10000));  // 460 N since 8.2 s
  ASSERT_EQ(c.Input(0, fw::kInputRegistersV2, r.data()), fw::kInputRegistersV2);
  EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 4]), 80.0, 1.0);
  EXPECT_NE(r[fw::kInStatus] & fw::kStatusOverload, 0);
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusBridgeFault, 0);
  EXPECT_EQ(UnpackU32(&r[fw::kInOverloadEvents]), 1u);
  EXPECT_GE(UnpackFloat32(&r[fw::kInPeaks + 4]), 455.0f);
  EXPECT_EQ(ftd.Stop(), 0);
}

/// Issue 17 item 7: a calibration file that cannot be used does not keep a field device down. It
/// comes up, logs why (file:line:column), runs on a valid slot B if there is one, and otherwise
/// serves the map with status bit 4 set and the wrench registers invalid.
TEST(FtdModbus, UnusableCalibrationFilesStillServeAndSayWhy) {
  const test::TempDir tmp("ftd_badcal");
  const std::string bad = tmp / "bad.json";
  {
    std::ofstream f(bad);
    f << "{\n  \"schema\": \"ftstack-cal/1\",\n  \"matrix\": [1, 2,\n";  // truncated JSON
  }
  const std::string good = tmp / "good.json";
  {
    const test::BuiltinAdc builtin = test::BuiltinSimAdc();
    const sim::SensorDescription desc = sim::DefaultSensorDescription();
    cal::SaveCalFile(good, sim::IdealCalibration(*desc.model, builtin.info));
  }
  auto status_of = [](test::FtdProcess& ftd,
                      std::array<std::uint16_t, fw::kInputRegisterCount>* r) {
    Client c(ftd.port());
    if (!c.WaitSamples(50)) return false;
    return c.Input(0, fw::kInputRegistersV2, r->data()) == fw::kInputRegistersV2;
  };
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  {  // bad A, good B: runs on B and says so
    test::FtdProcess ftd({"--sim-wrench", "0,0,50,0,0,0", "--cal", bad, "--cal-b", good,
                          "--modbus-tcp", "127.0.0.1:0"});
    ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
    ASSERT_TRUE(status_of(ftd, &r));
    EXPECT_EQ(r[fw::kInStatus] & fw::kStatusCalInvalid, 0);
    EXPECT_EQ(r[fw::kInCalSlot], 1);
    EXPECT_NEAR(UnpackFloat32(&r[fw::kInWrenchFloat + 4]), 50.0, 1.0);
    EXPECT_EQ(ftd.Stop(), 0);
    EXPECT_NE(ftd.Stderr().find(bad + ":4:1"), std::string::npos) << ftd.Stderr();
    EXPECT_NE(ftd.Stderr().find("slot B"), std::string::npos) << ftd.Stderr();
  }
  {  // bad A (corrupt) and bad B (missing): serves, bit 4 set, wrench invalid
    test::FtdProcess ftd(
        {"--cal", bad, "--cal-b", tmp / "missing.json", "--modbus-tcp", "127.0.0.1:0"});
    ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
    ASSERT_TRUE(status_of(ftd, &r));
    EXPECT_NE(r[fw::kInStatus] & fw::kStatusCalInvalid, 0);
    EXPECT_TRUE(std::isnan(UnpackFloat32(&r[fw::kInWrenchFloat + 4])));
    EXPECT_EQ(UnpackI32(&r[fw::kInWrenchInt + 4]), 0);
    EXPECT_EQ(ftd.Stop(), 0);
    EXPECT_NE(ftd.Stderr().find("missing.json"), std::string::npos) << ftd.Stderr();
    EXPECT_NE(ftd.Stderr().find("status bit 4"), std::string::npos) << ftd.Stderr();
  }
}

}  // namespace
}  // namespace ftstack
