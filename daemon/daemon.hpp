// The ftd daemon: sampling thread, Modbus TCP/RTU threads and the recording logger, as a library.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "daemon/backend.hpp"
#include "daemon/rdt_server.hpp"
#include "firmware/device.hpp"
#include "firmware/modbus_server.hpp"
#include "firmware/register_map.hpp"

namespace ftstack {
class RecordingWriter;
}  // namespace ftstack

namespace ftstack::daemon {

/// A start-up failure of the daemon; what() is the one-line reason.
class FtdError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything `ftd` is told on its command line (shared spec cli.md).
struct FtdOptions {
  std::string adc = "sim";                          ///< sim, hx711, spi
  std::optional<std::array<double, 6>> sim_wrench;  ///< constant applied wrench, N and N·m
  std::string replay;                               ///< recording whose wrench columns are played
  unsigned rate_hz = 1000;
  std::string cal;      ///< calibration file for slot 0 ("" = built-in)
  std::string cal_b;    ///< calibration file for slot 1 ("" = none)
  std::string payload;  ///< payload file for gravity compensation ("" = none)
  std::string rdt;      ///< HOST:PORT of the RDT server ("" = none)
  double rdt_counts_per_n = 1e6;
  double rdt_counts_per_nm = 1e6;
  unsigned rdt_buffer = 4;                 ///< records per packet in buffered RDT modes
  std::uint32_t rdt_status_mask = 0xFFFF;  ///< status bits copied into RDT records
  std::string modbus_tcp;                  ///< HOST:PORT ("" = no TCP server)
  std::string modbus_rtu;                  ///< serial device ("" = no RTU server)
  unsigned baud = 19200;
  char parity = 'N';
  unsigned unit_id = 1;
  std::string log;  ///< recording to write ("" = none)
  std::string gpiochip;
  std::string spidev;
  std::uint64_t seed = 1;
  bool paced = true;  ///< simulated ADC follows the wall clock (false: as fast as possible)
  /// Simulated ADC: hold the sampling thread sim_stall_ms on every sim_stall_every-th sample
  /// (0: never) — a deterministic stand-in for a preempted sampler (--sim-stall EVERY:MS).
  unsigned sim_stall_every = 0;
  double sim_stall_ms = 0;
};

/// Longest pause of the sampling loop after a backend call that failed at once (the back-off
/// doubles from one sample period up to this).
inline constexpr std::uint32_t kMaxBackoffUs = 100000;

/// Parses "HOST:PORT"; throws FtdError naming the bad part.
void ParseHostPort(const std::string& text, std::string* host, std::uint16_t* port);

/// CRC-32 of the fixed-point form of a calibration (little-endian: channel count, then per row
/// the N coefficients and the bias as int64 and the shift as uint8, then the rails as int32).
/// Reported in input registers 72–73 for the built-in calibration, which has no file.
[[nodiscard]] std::uint32_t FixedFormCrc(const fw::FixedCalibration& cal);

/// Live figures of a running daemon.
struct FtdStats {
  std::uint64_t samples = 0;  ///< samples processed by the sampling thread
  double elapsed_s = 0;       ///< since Start
  std::uint64_t logged_rows = 0;
  std::uint64_t log_dropped = 0;  ///< samples the logger could not keep up with
  bool sampling_ended = false;    ///< replay finished or the ADC failed for good
  std::uint64_t adc_errors = 0;   ///< failed sampling steps (timeouts, read errors)
  std::uint64_t backoffs = 0;     ///< pauses after a step that failed at once (no busy loop)
  std::string realtime;           ///< the sampling thread's scheduling and memory, one line
};

/// The running daemon. Start() spawns the threads; Stop() (or the destructor) joins them.
class Ftd {
 public:
  /// `simulator` makes the backend of `--adc sim` (nullptr in a board build: refused).
  explicit Ftd(FtdOptions options, SimulatorFactory simulator = nullptr);
  ~Ftd();
  Ftd(const Ftd&) = delete;
  Ftd& operator=(const Ftd&) = delete;

  /// Builds the sensor, calibration and servers and starts the threads. Throws FtdError.
  void Start();
  /// Stops and joins every thread, flushes the log. Idempotent.
  void Stop();
  /// Writes pending log rows (call from the non-real-time thread that owns the daemon).
  void DrainLog();

  [[nodiscard]] std::uint16_t tcp_port() const;
  [[nodiscard]] FtdStats stats() const;
  [[nodiscard]] fw::Device& device() { return *device_; }
  [[nodiscard]] fw::RegisterMap& register_map() { return *map_; }
  [[nodiscard]] const fw::ServerCounters* tcp_counters() const;
  /// The RDT server (nullptr without --rdt).
  [[nodiscard]] const RdtServer* rdt() const { return rdt_.get(); }
  /// One status line (no newline): sequence, wrench, status bits, sample rate, clients.
  [[nodiscard]] std::string StatusLine() const;

 private:
  void SamplingLoop();
  void StartRdt();
  void PrepareLog();  ///< checks that --log can be written, sizes the log ring
  void BackOff(std::uint32_t pause_us);

  FtdOptions opt_;
  SimulatorFactory simulator_ = nullptr;
  std::unique_ptr<AdcBackend> backend_;
  std::unique_ptr<fw::WrenchCore> core_;
  std::unique_ptr<fw::Device> device_;
  std::unique_ptr<fw::RegisterMap> map_;
  std::unique_ptr<fw::ModbusTcpServer> tcp_;
  std::unique_ptr<fw::ModbusRtuServer> rtu_;
  std::unique_ptr<RdtServer> rdt_;
  std::unique_ptr<RecordingWriter> writer_;

  // Single-producer (sampling thread) single-consumer (DrainLog) ring of published samples.
  std::vector<fw::DeviceSample> ring_;
  std::atomic<std::uint64_t> ring_head_{0};
  std::atomic<std::uint64_t> ring_tail_{0};
  std::atomic<std::uint64_t> log_dropped_{0};
  std::uint64_t logged_rows_ = 0;
  std::uint32_t last_logged_sequence_ = 0;
  std::uint64_t log_time_base_us_ = 0;
  std::uint32_t last_log_timestamp_us_ = 0;
  bool log_started_ = false;

  std::atomic<bool> stop_{false};
  std::atomic<bool> ended_{false};
  std::atomic<std::uint64_t> samples_{0};
  std::atomic<std::uint64_t> adc_errors_{0};
  std::atomic<std::uint64_t> backoffs_{0};
  std::string realtime_;
  std::uint64_t start_us_ = 0;
  std::uint64_t stop_us_ = 0;  ///< when Stop was called (0 while running)
  std::vector<std::thread> threads_;
  bool running_ = false;
};

}  // namespace ftstack::daemon
