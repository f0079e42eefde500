// The ftd daemon: composes backend, device, servers and logger; runs the sampling thread.
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
#include "daemon/calibration_set.hpp"
#include "daemon/http_server.hpp"
#include "daemon/mqtt_publisher.hpp"
#include "daemon/opcua_server.hpp"
#include "daemon/options.hpp"
#include "daemon/sample_log.hpp"
#include "daemon/servers.hpp"
#include "firmware/device.hpp"
#include "firmware/modbus_server.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::daemon {

/// Longest pause of the sampling loop after a backend call that failed at once (the back-off
/// doubles from one sample period up to this).
inline constexpr std::uint32_t kMaxBackoffUs = 100000;

/// Live figures of a running daemon.
struct FtdStats {
  std::uint64_t samples = 0;  ///< samples processed by the sampling thread
  double elapsed_s = 0;       ///< since Start
  std::uint64_t logged_rows = 0;
  std::uint64_t log_dropped = 0;   ///< samples the logger could not keep up with
  bool sampling_ended = false;     ///< replay finished or the ADC failed for good
  std::uint64_t adc_errors = 0;    ///< failed sampling steps (timeouts, read errors)
  std::uint64_t backoffs = 0;      ///< pauses after a step that failed at once (no busy loop)
  std::uint32_t late_samples = 0;  ///< missed sampling deadlines (input registers 74–75)
  std::string realtime;            ///< the sampling thread's scheduling and memory, one line
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
  [[nodiscard]] const RdtServer* rdt() const { return servers_.rdt(); }
  /// The Sparkplug B publisher (nullptr without --mqtt).
  [[nodiscard]] const MqttPublisher* mqtt() const { return mqtt_.get(); }
  /// The web server (nullptr without --http).
  [[nodiscard]] const HttpServer* http() const { return http_.get(); }
  /// One status line (no newline): sequence, wrench, status bits, sample rate, clients.
  [[nodiscard]] std::string StatusLine() const;

 private:
  /// The backend --adc names (the simulator's, or a hardware converter). Throws FtdError.
  void MakeBackend();
  /// Starts the sampling thread (real-time where granted) and one thread per server.
  void StartThreads();
  void SamplingLoop();
  void BackOff(std::uint32_t pause_us);
  /// Opens the web server of --http over the map; `cfg` gives the rated range and the slots.
  void OpenHttp(const fw::DeviceConfig& cfg);
  /// Opens the OPC UA server of --opcua over the map (device object from `cfg`).
  void OpenOpcua(const fw::DeviceConfig& cfg);
  /// The live figures the web page shows beside the map: sample rate, clients.
  [[nodiscard]] nlohmann::json WebRuntime() const;

  FtdOptions opt_;
  SimulatorFactory simulator_ = nullptr;
  std::unique_ptr<AdcBackend> backend_;
  std::unique_ptr<fw::WrenchCore> core_;
  std::unique_ptr<fw::Device> device_;
  std::unique_ptr<fw::RegisterMap> map_;
  Servers servers_;
  std::unique_ptr<MqttPublisher> mqtt_;
  std::unique_ptr<HttpServer> http_;
  std::unique_ptr<OpcuaServer> opcua_;
  SampleLog log_;

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
