// ftd's RDT server read by a client written here from ATI's published Net F/T RDT description
// (request: uint16 header 0x1234, uint16 command, uint32 sample count; record: uint32
// rdt_sequence, uint32 ft_sequence, uint32 status, int32 Fx Fy Fz Tx Ty Tz; all big-endian):
// 10 000 gapless records at 1 kHz matched to the Modbus wrench of the same sample, bias, stop,
// buffered mode, malformed requests beside other clients.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <arpa/inet.h>
#include <atomic>
#include <map>
#include <thread>

#include "firmware/register_map.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/sim_noise.hpp"

namespace ftstack {
namespace {

/// One RDT record as the description defines it.
struct Record {
  std::uint32_t rdt_sequence, ft_sequence, status;
  std::array<std::int32_t, 6> counts;
};

std::uint32_t Be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         p[3];
}

/// A UDP client of the RDT protocol.
class RdtClient {
 public:
  explicit RdtClient(int port) {
    fd_ = socket(AF_INET, SOCK_DGRAM, 0);
    const int rcvbuf = 8 << 20;
    setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<std::uint16_t>(port));
    inet_pton(AF_INET, "127.0.0.1", &to_.sin_addr);
  }
  ~RdtClient() { close(fd_); }
  void SendRaw(const std::vector<std::uint8_t>& bytes) {
    (void)sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to_), sizeof to_);
  }
  void Command(std::uint16_t command, std::uint32_t count) {
    SendRaw({0x12, 0x34, static_cast<std::uint8_t>(command >> 8),
             static_cast<std::uint8_t>(command & 0xFF), static_cast<std::uint8_t>(count >> 24),
             static_cast<std::uint8_t>(count >> 16), static_cast<std::uint8_t>(count >> 8),
             static_cast<std::uint8_t>(count)});
  }
  /// Receives one packet (up to timeout_ms); appends its records; returns the records in it
  /// (0: nothing arrived; -1: a packet that is not a whole number of records).
  int Receive(int timeout_ms, std::vector<Record>* out) {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return 0;
    std::uint8_t buf[2048];
    const ssize_t n = recv(fd_, buf, sizeof buf, 0);
    if (n <= 0 || n % 36 != 0) return -1;
    for (ssize_t k = 0; k < n; k += 36) {
      Record r{Be32(buf + k), Be32(buf + k + 4), Be32(buf + k + 8), {}};
      for (int a = 0; a < 6; ++a) {
        r.counts[static_cast<std::size_t>(a)] =
            static_cast<std::int32_t>(Be32(buf + k + 12 + 4 * a));
      }
      out->push_back(r);
    }
    return static_cast<int>(n / 36);
  }

 private:
  int fd_ = -1;
  sockaddr_in to_{};
};

int RdtPort(const test::FtdProcess& ftd) { return ftd.ServedPort("RDT"); }

/// 10 000 RDT records at rate_hz: gapless, and equal to the Modbus wrench of the same sample,
/// polled every poll_ms; each Modbus reply's timestamp (inputs 4–5) is its sample's own
/// conversion time, (sequence − 1) / rate_hz, however the sampling thread batches its reads.
void GaplessRecordsMatchModbus(const std::string& rate_hz, int poll_ms) {
  const std::uint32_t period_us = 1000000u / static_cast<std::uint32_t>(std::stoul(rate_hz));
  test::FtdProcess ftd({"--adc", "sim", "--sim-wrench", "20,-10,-150,0.5,-0.3,0.2", "--rate-hz",
                        rate_hz, "--modbus-tcp", "127.0.0.1:0", "--rdt", "127.0.0.1:0",
                        "--rdt-counts-per-n", "1000000", "--rdt-counts-per-nm", "1000000",
                        "--rdt-status-mask", "799"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  const int port = RdtPort(ftd);
  ASSERT_GT(port, 0) << ftd.Stderr();
  constexpr std::uint32_t kRecords = 10000;
  RdtClient rdt(port);
  std::vector<Record> got;
  got.reserve(kRecords);
  std::atomic<bool> done{false};
  // The Modbus side meanwhile: sequence and wrench from one reply (one sample).
  std::map<std::uint32_t, std::array<float, 6>> modbus;
  std::map<std::uint32_t, std::uint32_t> stamps;  // sequence → timestamp_us
  std::thread poller([&] {
    modbus_t* ctx = modbus_new_tcp("127.0.0.1", ftd.port());
    if (modbus_connect(ctx) != 0) return;
    while (!done) {
      std::uint16_t r[16];
      if (modbus_read_input_registers(ctx, fw::kInSequence, 16, r) == 16) {
        std::array<float, 6> w{};
        for (int a = 0; a < 6; ++a)
          w[static_cast<std::size_t>(a)] = fw::UnpackFloat32(&r[4 + 2 * a]);
        modbus[fw::UnpackU32(r)] = w;
        stamps[fw::UnpackU32(r)] = fw::UnpackU32(&r[fw::kInTimestampUs - fw::kInSequence]);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(poll_ms));
    }
    modbus_close(ctx);
    modbus_free(ctx);
  });
  rdt.Command(0x0002, kRecords);
  while (got.size() < kRecords) {
    if (rdt.Receive(2000, &got) <= 0) break;
  }
  done = true;
  poller.join();
  ASSERT_EQ(got.size(), kRecords);
  EXPECT_EQ(rdt.Receive(300, &got), 0) << "records after the requested count";
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].rdt_sequence, i + 1) << i;
    // --rdt-status-mask 799 keeps the fault bits only: the simulator's bit 7 (always set here)
    // is masked out. (Bit 9, late, may honestly appear on a busy host.)
    ASSERT_EQ(got[i].status & ~799u, 0u) << i;
    if (i > 0) {
      ASSERT_EQ(got[i].ft_sequence, got[i - 1].ft_sequence + 1) << i;
    }
  }
  // counts / counts-per-unit against the Modbus float wrench of the same ft_sequence.
  const std::uint32_t first = got.front().ft_sequence;
  int matched = 0;
  for (const auto& [seq, w] : modbus) {
    if (seq < first || seq >= first + kRecords) continue;
    const Record& r = got[seq - first];
    ASSERT_EQ(r.ft_sequence, seq);
    for (std::size_t a = 0; a < 6; ++a) {
      EXPECT_NEAR(r.counts[a] / 1e6, w[a], fw::AxisLsb(a)) << "axis " << a << " seq " << seq;
    }
    ++matched;
  }
  EXPECT_GE(matched, 100) << "Modbus reads that fell inside the stream";
  for (const auto& [seq, t_us] : stamps) {
    EXPECT_EQ(t_us, (seq - 1) * period_us) << "sequence " << seq;
  }
  EXPECT_EQ(ftd.Stop(SIGTERM), 0);
}

TEST(FtdRdt, TenThousandGaplessRecordsAt1kHzEqualTheModbusWrenchOfTheSameSample) {
  GaplessRecordsMatchModbus("1000", 37);
}

TEST(FtdRdt, At8kHzInBlocksEveryRecordStaysAndModbusTimesAreConversionTimes) {
  // The sampling thread reads 8 samples per wake-up here: still one record per sample, in order.
  GaplessRecordsMatchModbus("8000", 5);
}

TEST(FtdRdt, BiasStopBufferedAndMalformedRequestsBesideOtherClients) {
  const std::array<double, 6> applied = {20.0, -10.0, -150.0, 0.5, -0.3, 0.2};
  test::FtdProcess ftd({"--adc", "sim", "--sim-wrench", "20,-10,-150,0.5,-0.3,0.2", "--rate-hz",
                        "1000", "--rdt", "127.0.0.1:0", "--rdt-counts-per-n", "1000",
                        "--rdt-counts-per-nm", "100000", "--rdt-buffer", "5"},
                       false);
  const int port = RdtPort(ftd);
  ASSERT_GT(port, 0) << ftd.Stderr();
  const test::SimNoise noise = test::DeriveSimNoise();
  const double per_unit[6] = {1e3, 1e3, 1e3, 1e5, 1e5, 1e5};
  RdtClient a(port), b(port), c(port);
  std::vector<Record> ra, rb;
  a.Command(0x0002, 0);
  b.Command(0x0003, 0);
  for (int i = 0; i < 200; ++i) ASSERT_EQ(a.Receive(1000, &ra), 1);
  ASSERT_EQ(b.Receive(1000, &rb), 5);  // buffered: --rdt-buffer records per packet
  // Configurable counts: the applied wrench × counts per unit (5σ of one sample + 1 count).
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_NEAR(ra.back().counts[k] / per_unit[k], applied[k],
                5 * noise.sigma[k] + noise.fixed_error[k] + 1.0 / per_unit[k])
        << k;
  }
  // Malformed requests from a third client: short, long, wrong header, unknown command.
  c.SendRaw({0x12, 0x34, 0x00});
  c.SendRaw({0x12, 0x34, 0x00, 0x02, 0, 0, 0, 0, 0});
  c.SendRaw({0x43, 0x21, 0x00, 0x02, 0, 0, 0, 0});
  c.Command(0x0099, 0);
  EXPECT_EQ(c.Receive(200, &ra), 0) << "a malformed request started a stream";
  // Bias (software bias = tare, every output): records then read zero within the noise of a
  // sample minus a 100-sample average, and carry status bit 5.
  a.Command(0x0042, 0);
  bool biased = false;
  for (int i = 0; i < 2000 && !biased; ++i) {
    ASSERT_EQ(a.Receive(1000, &ra), 1);
    biased = (ra.back().status & fw::kStatusTareActive) != 0;
  }
  ASSERT_TRUE(biased);
  for (int i = 0; i < 10; ++i) ASSERT_EQ(a.Receive(1000, &ra), 1);
  for (std::size_t k = 0; k < 6; ++k) {
    const double tol = 5 * noise.sigma[k] * std::sqrt(1.0 + 1.0 / 100) + 2 * fw::AxisLsb(k);
    EXPECT_NEAR(ra.back().counts[k] / per_unit[k], 0.0, tol) << k;
  }
  // Stop: A's stream ends (after what was in flight); B's goes on.
  a.Command(0x0000, 0);
  while (a.Receive(100, &ra) > 0) {
  }
  EXPECT_EQ(a.Receive(300, &ra), 0) << "records after stop";
  while (rb.size() < 2000) ASSERT_EQ(b.Receive(1000, &rb), 5);
  // Neither client saw a gap, across the malformed requests, the bias and the other's stop.
  for (std::size_t i = 1; i < ra.size(); ++i) {
    ASSERT_EQ(ra[i].rdt_sequence, ra[i - 1].rdt_sequence + 1) << i;
    ASSERT_EQ(ra[i].ft_sequence, ra[i - 1].ft_sequence + 1) << i;
  }
  for (std::size_t i = 1; i < rb.size(); ++i) {
    ASSERT_EQ(rb[i].rdt_sequence, rb[i - 1].rdt_sequence + 1) << i;
    ASSERT_EQ(rb[i].ft_sequence, rb[i - 1].ft_sequence + 1) << i;
  }
  b.Command(0x0000, 0);
  EXPECT_EQ(ftd.Stop(SIGTERM), 0);
}

}  // namespace
}  // namespace ftstack
