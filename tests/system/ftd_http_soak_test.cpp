// Soak of ftd's web server: 50 clients poll the JSON API (a new connection per request, as a
// script would) while 10 event streams stay open; no errors, every reply one consistent sample,
// samples never going back, streams never stalling, ftd's memory flat and sampling alive.
// CI runs 5 s; FTSTACK_SOAK_SECONDS=60 build/tests/test_ftd_http_soak runs the long version. The
// client is plain POSIX sockets and HTTP/1.1 written here, independent of the server's library.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/system/ftd_process.hpp"
#include "tests/system/raw_connect.hpp"
#include "tests/system/soak.hpp"

namespace ftstack {
namespace {

using test::SoakSeconds;
using test::VmRssKb;

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;  // this test and ftd come from the same sanitizer build
#else
constexpr bool kSanitized = false;
#endif

/// A socket with send and receive timeouts, or -1.
int Open(int port, int timeout_ms) {
  const int fd = test::RawConnect(port);
  if (fd < 0) return -1;
  timeval tv{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof(tv));
  return fd;
}

bool SendAll(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = send(fd, s.data() + done, s.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string Get(const std::string& path) {
  return "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
}

/// One request on a new connection; the status code (-1 on a transport error), body in `body`.
int Request(int port, const std::string& path, std::string* body) {
  const int fd = Open(port, 5000);
  if (fd < 0) return -1;
  std::string reply;
  if (SendAll(fd, Get(path))) {
    char buf[4096];
    for (ssize_t n; (n = recv(fd, buf, sizeof(buf), 0)) > 0;) reply.append(buf, std::size_t(n));
  }
  close(fd);
  const std::size_t head_end = reply.find("\r\n\r\n");
  if (reply.rfind("HTTP/1.1 ", 0) != 0 || head_end == std::string::npos) return -1;
  *body = reply.substr(head_end + 4);
  return std::atoi(reply.c_str() + 9);
}

struct ClientResult {
  long replies = 0;
  long errors = 0;
  std::uint32_t first_sequence = 0;
  std::uint32_t last_sequence = 0;
  std::string first_problem;
  void Problem(const std::string& what) {
    ++errors;
    if (first_problem.empty()) first_problem = what;
  }
  /// A sample's sequence: never behind the previous one this client saw.
  void Saw(std::uint32_t seq) {
    if (replies > 0 && seq < last_sequence) {
      Problem("sequence went back: " + std::to_string(last_sequence) + " → " + std::to_string(seq));
    }
    if (replies == 0) first_sequence = seq;
    last_sequence = seq;
    ++replies;
  }
};

/// GET /api/v1/wrench and /api/v1/state in turn at about 10 Hz.
void Poll(int port, const std::atomic<bool>& stop, ClientResult* out) {
  const char* paths[2] = {"/api/v1/wrench", "/api/v1/state"};
  for (int i = 0; !stop; ++i) {
    std::string body;
    const int code = Request(port, paths[i % 2], &body);
    if (code != 200) {
      out->Problem(std::string(paths[i % 2]) + ": status " + std::to_string(code));
    } else {
      const auto j = nlohmann::json::parse(body, nullptr, false);
      if (j.is_discarded() || !j.contains("sequence") || !j.contains("wrench_n_nm")) {
        out->Problem(std::string(paths[i % 2]) + ": not a sample: " + body.substr(0, 80));
      } else {
        out->Saw(j["sequence"].get<std::uint32_t>());
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

/// One event stream at 10 Hz held open until stop; a gap of 2 s without an event is a stall.
void Stream(int port, const std::atomic<bool>& stop, ClientResult* out) {
  const int fd = Open(port, 2000);
  if (fd < 0 || !SendAll(fd, Get("/api/v1/stream?rate_hz=10"))) {
    out->Problem("stream: no connection");
    if (fd >= 0) close(fd);
    return;
  }
  std::string pending;
  char buf[4096];
  while (!stop) {
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) {
      out->Problem(n == 0 ? "stream closed by ftd" : "stream stalled for 2 s");
      break;
    }
    pending.append(buf, std::size_t(n));
    for (std::size_t eol; (eol = pending.find('\n')) != std::string::npos;) {
      const std::string line = pending.substr(0, eol);
      pending.erase(0, eol + 1);
      if (line.rfind("data: ", 0) != 0) continue;  // headers, chunk sizes, blank lines
      const auto j = nlohmann::json::parse(line.substr(6), nullptr, false);
      if (j.is_discarded() || !j.contains("sequence")) {
        out->Problem("stream event not a sample: " + line.substr(0, 80));
      } else {
        out->Saw(j["sequence"].get<std::uint32_t>());
      }
    }
  }
  close(fd);
}

TEST(FtdHttpSoak, FiftyPollersAndTenStreamsNoErrorsSamplesAdvanceMemoryFlat) {
  const double seconds = SoakSeconds();
  test::FtdProcess ftd({"--sim-wrench", "0,0,100,0,0,0", "--rate-hz", "1000", "--print-hz", "0",
                        "--modbus-tcp", "127.0.0.1:0", "--http", "127.0.0.1:0"});
  const int port = ftd.ServedPort("the web page");
  ASSERT_GT(port, 0) << ftd.Stderr();
  constexpr int kPollers = 50;
  constexpr int kStreams = 10;
  std::atomic<bool> stop{false};
  std::vector<ClientResult> res(kPollers + kStreams);
  std::vector<std::thread> threads;
  for (int i = 0; i < kPollers + kStreams; ++i) {
    threads.emplace_back(i < kPollers ? Poll : Stream, port, std::cref(stop), &res[std::size_t(i)]);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));  // every client connected
  const long rss_start_kb = VmRssKb(ftd.pid());
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const long rss_end_kb = VmRssKb(ftd.pid());
  stop = true;
  for (auto& t : threads) t.join();
  long replies = 0;
  for (std::size_t i = 0; i < res.size(); ++i) {
    const char* kind = i < kPollers ? "poller" : "stream";
    EXPECT_EQ(res[i].errors, 0) << kind << " " << i << ": " << res[i].first_problem;
    EXPECT_GT(res[i].replies, static_cast<long>(3 * seconds)) << kind << " " << i;
    // Not stale: each client saw the 1 kHz sampling advance by most of the run.
    EXPECT_GT(res[i].last_sequence - res[i].first_sequence,
              static_cast<std::uint32_t>(500 * seconds))
        << kind << " " << i;
    replies += res[i].replies;
  }
  ASSERT_GT(rss_start_kb, 0);
  // Flat: growth below 1 MiB over thousands of requests and connections. Under a sanitizer the
  // resident memory is the sanitizer's (ASan holds freed blocks in a quarantine of up to 256 MB,
  // TSan keeps shadow and history), so there LeakSanitizer at ftd's exit is the leak check.
  if (!kSanitized) {
    EXPECT_LT(rss_end_kb - rss_start_kb, 1024) << rss_start_kb << " kB → " << rss_end_kb << " kB";
  }
  std::printf("web soak %.0f s: %ld samples to %d pollers and %d streams, VmRSS %ld → %ld kB\n",
              seconds, replies, kPollers, kStreams, rss_start_kb, rss_end_kb);
  EXPECT_TRUE(ftd.alive());
  EXPECT_EQ(ftd.Stop(SIGTERM), 0) << ftd.Stderr();
  EXPECT_EQ(ftd.Stderr().find("ThreadSanitizer"), std::string::npos) << ftd.Stderr();
}

}  // namespace
}  // namespace ftstack
