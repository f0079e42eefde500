// ftd — the sensor daemon: ADC backend → firmware core → Modbus TCP/RTU slave (and a recording).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "daemon/daemon.hpp"
#include "tools/common.hpp"
#include "tools/ftd/http_options.hpp"
#include "tools/ftd/mqtt_options.hpp"
#include "tools/ftd/opcua_options.hpp"
#include "tools/ftd/source_options.hpp"
#if FTSTACK_FTD_SIMULATOR
#include "daemon/sim/sim_backend.hpp"
#endif

namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

/// The --rdt options (ATI Net F/T RDT server).
void AddRdtOptions(CLI::App& app, ftstack::daemon::FtdOptions& opt) {
  app.add_option("--rdt", opt.rdt,
                 "serve ATI Net F/T RDT over UDP on HOST:PORT (ATI's port: 49152; 0: any free)");
  app.add_option("--rdt-counts-per-n", opt.rdt_counts_per_n, "RDT counts per N (Fx Fy Fz)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rdt-counts-per-nm", opt.rdt_counts_per_nm, "RDT counts per N·m (Tx Ty Tz)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rdt-buffer", opt.rdt_buffer, "RDT records per packet in buffered mode")
      ->check(CLI::Range(1u, 40u));
  app.add_option("--rdt-status-mask", opt.rdt_status_mask,
                 "status bits copied into RDT records (default 0xFFFF: all)")
      ->check(CLI::Range(0u, 0xFFFFu));
}

/// ftd's exit codes (docs/spec: command lines).
enum ExitCode : int {
  kExitOk = 0,        ///< stopped by a signal, --duration-s or the end of a replay
  kExitRuntime = 1,   ///< failed while running (e.g. the log could not be written)
  kExitBadStart = 2,  ///< bad options, or the daemon could not start: one line on stderr
};

/// ftd's command line: the daemon's options and what the program itself does with them.
struct Args {
  ftstack::daemon::FtdOptions opt;
  std::string sim_wrench;
  std::string sim_stall;
  std::string parity = "N";
  double duration_s = 0;
  double print_hz = -1;
  bool unpaced = false;
  bool no_health_watch = false;
};

void AddOptions(CLI::App& app, Args& a) {
  ftstack::daemon::FtdOptions& opt = a.opt;
  ftstack::tools::AddSourceOptions(app, opt);
  app.add_option("--sim-wrench", a.sim_wrench,
                 "constant applied wrench FX,FY,FZ,MX,MY,MZ (N, N·m)");
  app.add_option("--rate-hz", opt.rate_hz, "sample rate, Hz")->check(CLI::Range(1u, 100000u));
  app.add_option("--cal", opt.cal,
                 "calibration file, slot 0 (default: the simulated sensor's own)");
  auto* cal_b =
      app.add_option("--cal-b", opt.cal_b, "calibration file for slot 1 (holding register 3)");
  app.add_option("--cal-dir", opt.cal_dir,
                 "slot directory of ftcal install: slots 0/1 from cal_A.json/cal_B.json, "
                 "starting on the active one")
      ->excludes(cal_b)
      ->check(CLI::ExistingDirectory);
  app.add_option("--payload", opt.payload,
                 "payload file (ftcal payload) for gravity compensation (holding 22–28)");
  app.add_option("--modbus-tcp", opt.modbus_tcp,
                 "serve Modbus TCP on HOST:PORT (port 0: any free)");
  app.add_option("--modbus-rtu", opt.modbus_rtu, "serve Modbus RTU on a serial DEVICE");
  AddRdtOptions(app, opt);
  ftstack::tools::AddHttpOptions(app, opt);
  ftstack::tools::AddOpcuaOptions(app, opt);
  ftstack::tools::AddMqttOptions(app, opt);
  app.add_option("--baud", opt.baud, "RTU baud rate")->check(CLI::Range(300u, 4000000u));
  app.add_option("--parity", a.parity, "RTU parity N|E|O")->check(CLI::IsMember({"N", "E", "O"}));
  app.add_option("--unit-id", opt.unit_id, "Modbus unit id")->check(CLI::Range(1u, 247u));
  app.add_option("--log", opt.log, "write published samples to a recording (CSV)");
  app.add_option("--duration-s", a.duration_s,
                 "stop after this many seconds (0: run until signalled)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", opt.seed, "noise seed of the simulated ADC");
  app.add_option("--print-hz", a.print_hz,
                 "rate of reading lines on stdout (default: 5, or 0 when stderr is a terminal and "
                 "shows the status line)");
  app.add_option("--sim-stall", a.sim_stall,
                 "simulated ADC: hold the sampling thread MS ms on every EVERY-th sample, "
                 "EVERY:MS (tests the late-sample counter)");
  app.add_flag("--unpaced", a.unpaced, "run the simulated ADC as fast as possible (benchmarks)");
  app.add_flag("--no-health-watch", a.no_health_watch,
               "run without the health watch (input 104 reads 0; measures what it costs)");
  app.add_option("--sim-effect", opt.sim_effects,
                 "inject NAME[:k=v,...] into the simulated sensor (ftsim record --effect; repeat)");
  app.add_option("--sim-profile", opt.sim_profile,
                 "load profile under --sim-effect (ftsim record --profile; default: --sim-wrench)");
  app.add_option("--sim-span-s", opt.sim_span_s, "span rendered with --sim-effect, s (then holds)")
      ->check(CLI::Range(1.0, 86400.0));
  app.add_option("--sim-speed", opt.sim_speed, "simulated seconds per wall-clock second (paced)")
      ->check(CLI::Range(0.01, 1000.0));
  app.add_flag("--sim-no-temperature{false}", opt.sim_temperature,
               "the simulated ADC reports no temperature (a converter without one, as an HX711)");
  app.get_option("--sim-wrench")->excludes(app.get_option("--replay"));
  app.get_option("--sim-effect")->excludes(app.get_option("--replay"));
}

/// Turns the program's own option texts into daemon options; throws std::invalid_argument.
void ResolveArgs(Args& a) {
  a.opt.parity = a.parity[0];
  a.opt.paced = !a.unpaced;
  a.opt.health_watch = !a.no_health_watch;
  try {
    if (!a.sim_wrench.empty()) a.opt.sim_wrench = ftstack::tools::ParseWrench(a.sim_wrench);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("--sim-wrench: ") + e.what());
  }
  if (!a.sim_stall.empty()) {
    unsigned every = 0;
    double ms = 0;
    char tail = 0;
    if (std::sscanf(a.sim_stall.c_str(), "%u:%lf%c", &every, &ms, &tail) != 2 || every < 1 ||
        !(ms > 0 && ms <= 10000)) {
      throw std::invalid_argument("--sim-stall '" + a.sim_stall +
                                  "': expected EVERY:MS (EVERY >= 1, 0 < MS <= 10000)");
    }
    a.opt.sim_stall_every = every;
    a.opt.sim_stall_ms = ms;
  }
}

/// Announces the servers on stderr.
void PrintServers(const ftstack::daemon::Ftd& ftd, const ftstack::daemon::FtdOptions& opt) {
  if (!opt.modbus_tcp.empty()) {
    const std::string host = opt.modbus_tcp.substr(0, opt.modbus_tcp.rfind(':'));
    std::fprintf(stderr, "ftd: serving Modbus TCP on %s:%u (unit %u and 255)\n", host.c_str(),
                 ftd.tcp_port(), opt.unit_id);
  }
  if (!opt.modbus_rtu.empty()) {
    std::fprintf(stderr, "ftd: serving Modbus RTU on %s, %u baud, 8%c1, unit %u\n",
                 opt.modbus_rtu.c_str(), opt.baud, opt.parity, opt.unit_id);
  }
  std::fflush(stderr);
}

/// Runs until a signal, --duration-s or the end of sampling: drains the log and prints the
/// status. Throws what DrainLog throws.
void Serve(ftstack::daemon::Ftd& ftd, double duration_s, double print_hz, bool status_line) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto next_status = t0;
  auto next_print = t0;
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ftd.DrainLog();
    const auto now = Clock::now();
    if (status_line && now >= next_status) {
      std::fprintf(stderr, "\r%s\x1b[K", ftd.StatusLine().c_str());
      next_status = now + std::chrono::milliseconds(200);
    }
    if (print_hz > 0 && now >= next_print) {
      std::printf("%s\n", ftd.StatusLine().c_str());
      std::fflush(stdout);
      next_print = now + std::chrono::duration_cast<Clock::duration>(
                             std::chrono::duration<double>(1.0 / print_hz));
    }
    if (ftd.stats().sampling_ended) break;
    if (duration_s > 0 && std::chrono::duration<double>(now - t0).count() >= duration_s) break;
  }
}

/// The closing summary on stderr.
void PrintSummary(const ftstack::daemon::FtdStats& st) {
  std::fprintf(stderr, "ftd: %llu samples in %.2f s (%.0f Hz), %u late%s\n",
               static_cast<unsigned long long>(st.samples), st.elapsed_s,
               st.elapsed_s > 0 ? static_cast<double>(st.samples) / st.elapsed_s : 0.0,
               st.late_samples, st.log_dropped > 0 ? " — log dropped samples" : "");
  if (st.adc_errors > 0) {
    std::fprintf(stderr, "ftd: %llu failed ADC steps, %llu back-off pauses\n",
                 static_cast<unsigned long long>(st.adc_errors),
                 static_cast<unsigned long long>(st.backoffs));
  }
}

int Run(int argc, char** argv) {
  using namespace ftstack;
  CLI::App app{"ftd — force/torque sensor daemon (firmware main loop on a board or host)"};
  Args args;
  AddOptions(app, args);
  CLI11_PARSE(app, argc, argv);
  const daemon::FtdOptions& opt = args.opt;
  try {
    ResolveArgs(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return kExitBadStart;
  }

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGPIPE, SIG_IGN);
#if FTSTACK_FTD_SIMULATOR
  daemon::Ftd ftd(opt, &daemon::MakeSimulatedBackend);
#else
  daemon::Ftd ftd(opt);  // a board build: --adc sim is refused with a clear message
#endif
  try {
    ftd.Start();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return kExitBadStart;
  }
  PrintServers(ftd, opt);

  const bool status_line = isatty(STDERR_FILENO) != 0;
  const double print_hz = args.print_hz < 0 ? (status_line ? 0 : 5) : args.print_hz;
  try {
    Serve(ftd, args.duration_s, print_hz, status_line);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nftd: %s\n", e.what());
    ftd.Stop();
    return kExitRuntime;
  }
  ftd.Stop();
  if (status_line) std::fprintf(stderr, "\n");
  PrintSummary(ftd.stats());
  ftstack::tools::PrintMqttSummary(ftd);
  return kExitOk;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {  // nothing is expected here; never die with a trace
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return kExitRuntime;
  }
}
