// Soak (issue 15): 16 libmodbus clients poll the real ftd while one writes holding registers and
// two send malformed frames; no errors, no stale or inconsistent replies, ftd's memory flat.
// CI runs 5 s; FTSTACK_SOAK_SECONDS=60 build/tests/test_ftd_soak runs the long version. The
// same test is the TSan stage's (ftd's sampling, Modbus and logger threads under a write load).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <thread>

#include "firmware/register_map.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/raw_connect.hpp"
#include "tests/system/soak.hpp"

namespace ftstack {
namespace {

using test::SoakSeconds;
using test::VmRssKb;

using fw::UnpackFloat32;
using fw::UnpackU32;

modbus_t* Connect(int port) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  modbus_set_response_timeout(ctx, 2, 0);
  if (modbus_connect(ctx) != 0) {
    modbus_free(ctx);
    return nullptr;
  }
  return ctx;
}

using test::RawConnect;

struct PollerResult {
  long replies = 0;
  long errors = 0;
  long inconsistent = 0;  ///< map version, sequence order, timestamp or wrench wrong
  std::uint32_t first_sequence = 0;
  std::uint32_t last_sequence = 0;
  std::string first_problem;
};

/// Polls every input register; each reply must be one consistent sample, never older than the
/// previous one (sequence and timestamp move together), with the applied Fz.
void Poll(int port, const std::atomic<bool>& stop, PollerResult* out) {
  modbus_t* ctx = Connect(port);
  if (ctx == nullptr) {
    out->errors = 1;
    out->first_problem = "connect failed";
    return;
  }
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  std::uint32_t prev_seq = 0;
  std::uint32_t prev_ts = 0;
  bool have_prev = false;
  auto problem = [&](const std::string& what) {
    if (out->inconsistent++ == 0 && out->first_problem.empty()) out->first_problem = what;
  };
  while (!stop.load()) {
    if (modbus_read_input_registers(ctx, 0, fw::kInputRegistersV2, r.data()) !=
        static_cast<int>(fw::kInputRegistersV2)) {
      if (out->errors++ == 0) out->first_problem = modbus_strerror(errno);
      continue;
    }
    ++out->replies;
    const std::uint32_t seq = UnpackU32(&r[fw::kInSequence]);
    const std::uint32_t ts = UnpackU32(&r[fw::kInTimestampUs]);
    if (r[fw::kInMapVersion] != fw::kMapVersion) problem("map version " + std::to_string(r[0]));
    if (have_prev) {
      if (seq < prev_seq) problem("sequence went back");
      if (seq == prev_seq && ts != prev_ts) problem("same sample, other timestamp");
      if (seq > prev_seq && ts <= prev_ts) problem("newer sample, older timestamp");
    } else {
      out->first_sequence = seq;
    }
    if (std::fabs(UnpackFloat32(&r[fw::kInWrenchFloat + 4]) - 100.0f) > 5.0f) {
      problem("Fz " + std::to_string(UnpackFloat32(&r[fw::kInWrenchFloat + 4])));
    }
    prev_seq = seq;
    prev_ts = ts;
    have_prev = true;
  }
  out->last_sequence = prev_seq;
  modbus_close(ctx);
  modbus_free(ctx);
}

/// Writes holding registers (filter length) and reads each value back: the only writer, so the
/// read-back must be what it wrote.
void WriteHolding(int port, const std::atomic<bool>& stop, PollerResult* out) {
  modbus_t* ctx = Connect(port);
  if (ctx == nullptr) {
    out->errors = 1;
    return;
  }
  std::uint16_t len = 1;
  while (!stop.load()) {
    len = static_cast<std::uint16_t>(len % 16 + 1);
    std::uint16_t back = 0;
    if (modbus_write_register(ctx, fw::kHoldFilterLength, len) != 1 ||
        modbus_read_registers(ctx, fw::kHoldFilterLength, 1, &back) != 1) {
      if (out->errors++ == 0) out->first_problem = modbus_strerror(errno);
      continue;
    }
    ++out->replies;
    if (back != len && out->inconsistent++ == 0) out->first_problem = "holding read-back differs";
  }
  modbus_close(ctx);
  modbus_free(ctx);
}

/// Malformed traffic: random bytes, half frames, wrong protocol ids, random function codes.
void Barrage(int port, unsigned seed, const std::atomic<bool>& stop, long* sent) {
  std::mt19937 rng(seed);
  while (!stop.load()) {
    const int fd = RawConnect(port);
    if (fd < 0) continue;
    const int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    timeval tv{0, 20000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    std::vector<std::uint8_t> f;
    switch (rng() % 4) {
      case 0:  // random bytes
        f.resize(1 + rng() % 300);
        for (auto& b : f) b = static_cast<std::uint8_t>(rng());
        break;
      case 1:  // half a valid request, then the connection closes
        f = {0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x01, 0x04, 0x00};
        f.resize(1 + rng() % f.size());
        break;
      case 2:  // a wrong protocol id
        f = {0x00, 0x02, static_cast<std::uint8_t>(1 + rng() % 255),
             0x00, 0x00, 0x06,
             0x01, 0x04, 0x00,
             0x00, 0x00, 0x01};
        break;
      default: {  // well framed, random function code and body
        const std::size_t pdu = 1 + rng() % 20;
        f = {0x12, 0x34, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(pdu + 1), 0x01};
        for (std::size_t k = 0; k < pdu; ++k) f.push_back(static_cast<std::uint8_t>(rng()));
        break;
      }
    }
    if (send(fd, f.data(), f.size(), MSG_NOSIGNAL) > 0) ++*sent;
    std::uint8_t rsp[300];
    (void)recv(fd, rsp, sizeof(rsp), 0);  // a reply, a close or the 20 ms timeout
    close(fd);
  }
}

TEST(FtdSoak, SixteenClientsAndAMalformedBarrageNoErrorsNoStaleRepliesMemoryFlat) {
  const double seconds = SoakSeconds();
  const test::TempDir tmp("ftd_soak");  // the logger thread writes a recording all along
  test::FtdProcess ftd({"--sim-wrench", "0,0,100,0,0,0", "--rate-hz", "1000", "--modbus-tcp",
                        "127.0.0.1:0", "--log", tmp / "soak.csv"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  std::atomic<bool> stop{false};
  constexpr int kPollers = 15;  // + 1 writer of holding registers = 16 libmodbus clients
  std::vector<PollerResult> res(kPollers + 1);
  std::vector<std::thread> threads;
  for (int i = 0; i < kPollers; ++i) {
    threads.emplace_back(Poll, ftd.port(), std::cref(stop), &res[static_cast<std::size_t>(i)]);
  }
  threads.emplace_back(WriteHolding, ftd.port(), std::cref(stop), &res[kPollers]);
  long junk[2] = {0, 0};
  for (unsigned k = 0; k < 2; ++k) {
    threads.emplace_back(Barrage, ftd.port(), 15 + k, std::cref(stop), &junk[k]);
  }
  // Memory after a warm-up with every client connected, and at the end.
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const long rss_start_kb = VmRssKb(ftd.pid());
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const long rss_end_kb = VmRssKb(ftd.pid());
  stop = true;
  for (auto& t : threads) t.join();
  long replies = 0;
  for (std::size_t i = 0; i < res.size(); ++i) {
    EXPECT_EQ(res[i].errors, 0) << "client " << i << ": " << res[i].first_problem;
    EXPECT_EQ(res[i].inconsistent, 0) << "client " << i << ": " << res[i].first_problem;
    EXPECT_GT(res[i].replies, 10) << "client " << i;
    replies += res[i].replies;
    if (i < kPollers) {  // not stale: each poller saw the samples advance (1 kHz for seconds)
      EXPECT_GT(res[i].last_sequence - res[i].first_sequence,
                static_cast<std::uint32_t>(300 * seconds))
          << "client " << i;
    }
  }
  EXPECT_GT(junk[0] + junk[1], 20);
  ASSERT_GT(rss_start_kb, 0);
  // Flat: growth below 1 MiB (a leak of a few bytes per request would show: there are many
  // thousands of requests).
  EXPECT_LT(rss_end_kb - rss_start_kb, 1024) << rss_start_kb << " kB → " << rss_end_kb << " kB";
  std::printf(
      "soak %.0f s: %ld replies to 16 clients, %ld malformed connections, VmRSS %ld → %ld kB\n",
      seconds, replies, junk[0] + junk[1], rss_start_kb, rss_end_kb);
  EXPECT_TRUE(ftd.alive());
  EXPECT_EQ(ftd.Stop(SIGTERM), 0) << ftd.Stderr();
  EXPECT_EQ(ftd.Stderr().find("ThreadSanitizer"), std::string::npos) << ftd.Stderr();
  // The logger kept up: the recording holds about a row per sample of the run.
  std::ifstream rec(tmp / "soak.csv");
  long rows = 0;
  for (std::string line; std::getline(rec, line);) ++rows;
  EXPECT_GT(rows, static_cast<long>(500 * seconds)) << "rows in the recording";
}

}  // namespace
}  // namespace ftstack
