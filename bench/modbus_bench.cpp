// Modbus TCP throughput and latency of ftd vs a plain libmodbus server; host sample rate sustained.
#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>
#include <vector>

#include "daemon/daemon.hpp"
#include "daemon/sim/sim_backend.hpp"
#include "firmware/register_map.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double RunSeconds() {
  const char* s = std::getenv("FTSTACK_BENCH_SECONDS");
  const double v = s != nullptr ? std::strtod(s, nullptr) : 1.0;
  return v > 0 ? v : 1.0;
}

/// The daemon as `./ftstack.sh run` starts it, sampling the simulated sensor at `rate_hz`.
ftstack::daemon::Ftd& Daemon(unsigned rate_hz, bool paced) {
  static std::unique_ptr<ftstack::daemon::Ftd> d;
  static unsigned d_rate = 0;
  static bool d_paced = true;
  if (!d || d_rate != rate_hz || d_paced != paced) {
    d.reset();
    ftstack::daemon::FtdOptions o;
    o.rate_hz = rate_hz;
    o.paced = paced;
    o.sim_wrench = std::array<double, 6>{10, 0, -50, 0, 0.5, 0};
    o.modbus_tcp = "127.0.0.1:0";
    d = std::make_unique<ftstack::daemon::Ftd>(o, &ftstack::daemon::MakeSimulatedBackend);
    d->Start();
    d_rate = rate_hz;
    d_paced = paced;
  }
  return *d;
}

/// A plain libmodbus TCP server (select loop, modbus_receive + modbus_reply) over a mapping with
/// the same input registers (all of the map), in its own thread: the reference the daemon is
/// compared with.
class PlainServer {
 public:
  PlainServer() {
    ctx_ = modbus_new_tcp("127.0.0.1", 0);
    mapping_ = modbus_mapping_new(0, 0, ftstack::fw::kHoldingRegisterSpan,
                                  ftstack::fw::kInputRegisterCount);
    for (int i = 0; i < ftstack::fw::kInputRegisterCount; ++i) mapping_->tab_input_registers[i] = i;
    listen_ = modbus_tcp_listen(ctx_, 32);
    sockaddr_in a{};
    socklen_t len = sizeof(a);
    getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { Loop(); });
  }
  ~PlainServer() {
    stop_ = true;
    thread_.join();
    for (int fd = 0; fd <= max_fd_; ++fd) {
      if (FD_ISSET(fd, &all_)) close(fd);
    }
    modbus_mapping_free(mapping_);
    modbus_free(ctx_);
  }
  [[nodiscard]] int port() const { return port_; }

 private:
  void Loop() {
    FD_ZERO(&all_);
    FD_SET(listen_, &all_);
    max_fd_ = listen_;
    std::vector<std::uint8_t> query(MODBUS_TCP_MAX_ADU_LENGTH);
    while (!stop_) {
      fd_set ready = all_;
      timeval tv{0, 100000};
      if (select(max_fd_ + 1, &ready, nullptr, nullptr, &tv) <= 0) continue;
      for (int fd = 0; fd <= max_fd_; ++fd) {
        if (!FD_ISSET(fd, &ready)) continue;
        if (fd == listen_) {
          const int c = accept(listen_, nullptr, nullptr);
          if (c >= 0) {
            FD_SET(c, &all_);
            max_fd_ = std::max(max_fd_, c);
          }
          continue;
        }
        modbus_set_socket(ctx_, fd);
        const int rc = modbus_receive(ctx_, query.data());
        if (rc > 0) {
          modbus_reply(ctx_, query.data(), rc, mapping_);
        } else if (rc == -1) {
          close(fd);
          FD_CLR(fd, &all_);
        }
      }
    }
  }

  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int listen_ = -1;
  int port_ = 0;
  fd_set all_{};
  int max_fd_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

PlainServer& Plain() {
  static PlainServer s;
  return s;
}

struct LoadResult {
  std::uint64_t transactions = 0;
  std::uint64_t errors = 0;
  double seconds = 0;
  double p50_us = 0;
  double p99_us = 0;
};

/// `clients` libmodbus clients, each reading all input registers back to back for `seconds`.
LoadResult Hammer(int port, int clients, double seconds) {
  std::vector<std::vector<float>> lat(static_cast<std::size_t>(clients));
  std::atomic<std::uint64_t> errors{0};
  std::atomic<bool> go{false}, stop{false};
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(clients));
  for (int i = 0; i < clients; ++i) {
    threads.emplace_back([&, i] {
      modbus_t* c = modbus_new_tcp("127.0.0.1", port);
      modbus_set_response_timeout(c, 2, 0);
      if (modbus_connect(c) != 0) {
        ++errors;
        modbus_free(c);
        return;
      }
      std::uint16_t regs[ftstack::fw::kInputRegistersV2];
      auto& mine = lat[static_cast<std::size_t>(i)];
      mine.reserve(200000);
      while (!go) std::this_thread::yield();
      while (!stop) {
        const auto t0 = Clock::now();
        if (modbus_read_input_registers(c, 0, ftstack::fw::kInputRegistersV2, regs) !=
            ftstack::fw::kInputRegistersV2) {
          if (errors++ == 0) std::fprintf(stderr, "first error: %s\n", modbus_strerror(errno));
          continue;
        }
        mine.push_back(std::chrono::duration<float, std::micro>(Clock::now() - t0).count());
      }
      modbus_close(c);
      modbus_free(c);
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // let every client connect
  const auto t0 = Clock::now();
  go = true;
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  stop = true;
  const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
  for (auto& t : threads) t.join();
  std::vector<float> all;
  for (auto& v : lat) all.insert(all.end(), v.begin(), v.end());
  LoadResult r;
  r.transactions = all.size();
  r.errors = errors;
  r.seconds = elapsed;
  if (!all.empty()) {
    auto pct = [&](double p) {
      const std::size_t k = std::min(all.size() - 1, static_cast<std::size_t>(p * all.size()));
      std::nth_element(all.begin(), all.begin() + static_cast<long>(k), all.end());
      return static_cast<double>(all[k]);
    };
    r.p50_us = pct(0.50);
    r.p99_us = pct(0.99);
  }
  return r;
}

void Report(benchmark::State& state, const LoadResult& r) {
  state.counters["tx_per_s"] = static_cast<double>(r.transactions) / r.seconds;
  state.counters["p50_us"] = r.p50_us;
  state.counters["p99_us"] = r.p99_us;
  state.counters["errors"] = static_cast<double>(r.errors);
}

/// ftd sampling the simulated sensor at 8 kHz while `clients` poll it; also reports the sample
/// rate the sampling thread sustained during the run.
void BM_FtdTcp(benchmark::State& state) {
  ftstack::daemon::Ftd& d = Daemon(8000, true);
  const double seconds = RunSeconds();
  LoadResult r;
  double rate = 0;
  for (auto _ : state) {
    const auto s0 = d.stats();
    r = Hammer(d.tcp_port(), static_cast<int>(state.range(0)), seconds);
    const auto s1 = d.stats();
    rate = static_cast<double>(s1.samples - s0.samples) / (s1.elapsed_s - s0.elapsed_s);
    state.SetIterationTime(r.seconds);
  }
  Report(state, r);
  state.counters["sample_hz"] = rate;
}

/// The plain libmodbus server, same register count, same clients, same run.
void BM_PlainTcp(benchmark::State& state) {
  PlainServer& p = Plain();
  LoadResult r;
  for (auto _ : state) {
    r = Hammer(p.port(), static_cast<int>(state.range(0)), RunSeconds());
    state.SetIterationTime(r.seconds);
  }
  Report(state, r);
}

/// The highest sample rate the host reaches: the simulated ADC unpaced (sensor model, noise,
/// counts, core, transform, overload, publication) while `clients` poll over Modbus.
void BM_FtdUnpacedSampleRate(benchmark::State& state) {
  ftstack::daemon::Ftd& d = Daemon(8000, false);
  double rate = 0;
  LoadResult r;
  for (auto _ : state) {
    const auto s0 = d.stats();
    r = Hammer(d.tcp_port(), static_cast<int>(state.range(0)), RunSeconds());
    const auto s1 = d.stats();
    rate = static_cast<double>(s1.samples - s0.samples) / (s1.elapsed_s - s0.elapsed_s);
    state.SetIterationTime(r.seconds);
  }
  Report(state, r);
  state.counters["sample_hz"] = rate;
}

}  // namespace

int main(int argc, char** argv) {
  // ftd and the plain server alternate per client count, so a change in machine load during the
  // run affects both sides of each ratio alike.
  for (const int clients : {1, 4, 16}) {
    benchmark::RegisterBenchmark("BM_FtdTcp", BM_FtdTcp)
        ->Arg(clients)
        ->Iterations(1)
        ->UseManualTime();
    benchmark::RegisterBenchmark("BM_PlainTcp", BM_PlainTcp)
        ->Arg(clients)
        ->Iterations(1)
        ->UseManualTime();
  }
  benchmark::RegisterBenchmark("BM_FtdUnpacedSampleRate", BM_FtdUnpacedSampleRate)
      ->Arg(4)
      ->Iterations(1)
      ->UseManualTime();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
