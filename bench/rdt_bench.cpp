// RDT streaming: records per second each client receives from ftd, with 1 and 4 clients, next to
// the sampling rate the daemon sustained in the same run.
#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <thread>
#include <vector>

#include "daemon/daemon.hpp"
#include "daemon/sim/sim_backend.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double RunSeconds() {
  const char* s = std::getenv("FTSTACK_BENCH_SECONDS");
  const double v = s != nullptr ? std::strtod(s, nullptr) : 1.0;
  return v > 0 ? v : 1.0;
}

struct ClientResult {
  std::uint64_t records = 0;
  std::uint64_t gaps = 0;  ///< missing rdt_sequence numbers
};

/// One RDT client: start real-time streaming, count records and gaps for `seconds`, stop.
ClientResult Stream(std::uint16_t port, double seconds) {
  ClientResult r;
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const int rcvbuf = 8 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  auto command = [&](std::uint8_t cmd) {
    const std::uint8_t req[8] = {0x12, 0x34, 0, cmd, 0, 0, 0, 0};
    (void)sendto(fd, req, sizeof req, 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  };
  command(0x02);
  std::uint32_t last = 0;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  std::uint8_t buf[2048];
  while (Clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    for (ssize_t k = 0; k + 36 <= n; k += 36) {
      const std::uint32_t seq = (std::uint32_t{buf[k]} << 24) | (std::uint32_t{buf[k + 1]} << 16) |
                                (std::uint32_t{buf[k + 2]} << 8) | buf[k + 3];
      if (last != 0 && seq > last + 1) r.gaps += seq - last - 1;
      last = seq;
      ++r.records;
    }
  }
  command(0x00);
  close(fd);
  return r;
}

/// Args: clients, sample rate (Hz; 0 = simulated ADC unpaced, as fast as the host runs).
void BM_Rdt(benchmark::State& state) {
  const int clients = static_cast<int>(state.range(0));
  const auto rate = static_cast<unsigned>(state.range(1));
  ftstack::daemon::FtdOptions o;
  o.rate_hz = rate > 0 ? rate : 8000;
  o.paced = rate > 0;
  o.sim_wrench = std::array<double, 6>{10, 0, -50, 0, 0.5, 0};
  o.rdt = "127.0.0.1:0";
  ftstack::daemon::Ftd ftd(o, &ftstack::daemon::MakeSimulatedBackend);
  ftd.Start();
  const double seconds = RunSeconds();
  double min_rate = 0, gaps = 0, sample_hz = 0;
  for (auto _ : state) {
    std::vector<ClientResult> results(static_cast<std::size_t>(clients));
    std::vector<std::thread> threads;
    const std::uint64_t s0 = ftd.stats().samples;
    const auto t0 = Clock::now();
    for (int c = 0; c < clients; ++c) {
      threads.emplace_back(
          [&, c] { results[static_cast<std::size_t>(c)] = Stream(ftd.rdt()->port(), seconds); });
    }
    for (auto& t : threads) t.join();
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    sample_hz = static_cast<double>(ftd.stats().samples - s0) / dt;
    min_rate = 1e300;
    gaps = 0;
    for (const auto& r : results) {
      min_rate = std::min(min_rate, static_cast<double>(r.records) / seconds);
      gaps += static_cast<double>(r.gaps);
    }
  }
  state.counters["records_per_s"] = min_rate;  // the slowest client's
  state.counters["sample_hz"] = sample_hz;
  state.counters["gaps"] = gaps;
  state.counters["overruns"] = static_cast<double>(ftd.rdt()->stats().ring_overruns);
  state.counters["send_errors"] = static_cast<double>(ftd.rdt()->stats().send_errors);
  ftd.Stop();
}
BENCHMARK(BM_Rdt)
    ->Args({1, 1000})
    ->Args({4, 1000})
    ->Args({1, 7000})
    ->Args({4, 7000})
    ->Args({1, 0})
    ->Args({4, 0})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
