// ftd's Sparkplug B edge node over MQTT (libmosquitto): births, decimated wrench, commands.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "daemon/options.hpp"
#include "daemon/sparkplug_metrics.hpp"
#include "firmware/register_map.hpp"

struct mosquitto;
struct mosquitto_message;

namespace ftstack::daemon {

/// A parsed broker URL.
struct BrokerUrl {
  bool tls = false;
  std::string host;
  std::uint16_t port = 1883;
};
/// Parses mqtt://HOST[:PORT] and mqtts://HOST[:PORT] (default ports 1883, 8883); throws FtdError.
[[nodiscard]] BrokerUrl ParseBrokerUrl(const std::string& url);

/// Live counters (any thread).
struct MqttStats {
  bool connected = false;
  std::uint64_t published = 0;   ///< messages handed to the broker connection (births, data)
  std::uint64_t dropped = 0;     ///< wrench windows never published (queue full or no broker)
  std::uint32_t reconnects = 0;  ///< connections made after the first
  std::uint32_t births = 0;      ///< NBIRTH messages sent
  std::uint32_t commands = 0;    ///< DCMD commands handled (accepted or refused)
};

/// The edge node. Push() is the sampling thread's only call: it adds the sample to the current
/// window and, when the window is complete, queues it without blocking (a full queue counts a
/// drop). Run() is the publishing thread: connection with back-off, NBIRTH + DBIRTH after every
/// connection and on Node Control/Rebirth, one DDATA per window (wrench, plus what changed),
/// commands (tare, clear peaks) through the register map, NDEATH as the will and on Stop.
class MqttPublisher {
 public:
  /// `device_id`: the default device name (used when the options name none).
  MqttPublisher(const FtdOptions& options, fw::RegisterMap* map, std::string device_id);
  ~MqttPublisher();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  /// Checks the options, reads the credentials and sets up TLS; throws FtdError. Connecting is
  /// Run's job (a broker that is down at start is retried, not fatal).
  void Open();
  /// Sampling thread only: lock-free, no heap, never waits.
  void Push(const fw::DeviceSample& d);
  /// Publishes until `stop`, then sends NDEATH and disconnects.
  void Run(const std::atomic<bool>& stop);

  [[nodiscard]] MqttStats stats() const;
  [[nodiscard]] const std::string& edge_node() const { return node_; }
  [[nodiscard]] const std::string& device() const { return device_; }
  /// Counters the register map serves (input registers 200–209).
  [[nodiscard]] const fw::MqttCounters& counters() const { return counters_; }

 private:
  static constexpr std::size_t kQueueSize = 256;

  void Connect();
  void OnConnect(int rc);
  void OnMessage(const mosquitto_message& msg);
  void HandleCommands(const std::vector<sparkplug::Metric>& metrics);
  void PublishBirth();
  void PublishWindow(const WrenchWindow& w);
  bool Send(const std::string& topic, const std::vector<std::uint8_t>& payload, int qos);
  std::vector<std::uint8_t> DeathPayload() const;
  DeviceState ReadState();
  void Disconnected();

  FtdOptions opt_;
  fw::RegisterMap* map_;
  BrokerUrl url_;
  std::string node_, device_;
  mosquitto* mosq_ = nullptr;

  // Sampling thread: the window being summed and the queue's producer side.
  WrenchWindow window_{};
  std::uint32_t window_us_ = 100000;
  std::array<WrenchWindow, kQueueSize> queue_{};  ///< single producer, single consumer
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};

  // Publishing thread.
  bool connected_ = false;
  bool socket_open_ = false;
  bool birth_due_ = false;
  bool ever_connected_ = false;
  std::uint64_t next_attempt_us_ = 0;
  std::uint32_t backoff_ms_ = 0;
  std::uint8_t bd_seq_ = 0;       ///< of the current connection (its will and NBIRTH)
  std::uint8_t next_bd_seq_ = 0;  ///< +1 per connection attempt, wraps 255 -> 0
  std::uint8_t seq_ = 0;
  std::vector<sparkplug::Metric> sent_;  ///< exception metrics as last published
  DeviceState state_{};
  WrenchWindow last_window_{};  ///< the latest window (DBIRTH's wrench values)
  fw::MqttCounters counters_{};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint32_t> reconnects_{0}, births_{0}, commands_{0};
  std::atomic<bool> connected_flag_{false};
};

/// The default device name: the serial of the calibration file ftd starts on, else "ft-" and the
/// active calibration's CRC in hex; characters Sparkplug forbids in a name ('/', '+', '#') and
/// spaces become '_'.
[[nodiscard]] std::string DefaultDeviceId(const FtdOptions& opt, std::uint8_t slot,
                                          std::uint32_t cal_crc);

}  // namespace ftstack::daemon
