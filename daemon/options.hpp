// ftd's options (its command line as a struct) and the daemon's start-up error type.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "measurement/units.hpp"

namespace ftstack::daemon {

/// A start-up failure of the daemon; what() is the one-line reason.
class FtdError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything `ftd` is told on its command line (shared spec cli.md).
struct FtdOptions {
  std::string adc = "sim";                          ///< sim, hx711, spi, replay
  std::optional<std::array<double, 6>> sim_wrench;  ///< constant applied wrench, N and N·m
  /// Recording played: its wrench columns through the simulated sensor (--adc sim), or its bridge
  /// columns as the calibration's converter (--adc replay, read in replay_units if declared).
  std::string replay;
  UnitOverrides replay_units;
  /// Effects injected into the simulated sensor (--sim-effect, ftsim record's vocabulary); with
  /// them (or a sim_profile) the bridges are composed (at start-up, or piecewise when long) over
  /// sim_span_s of sim_profile (a profile of ftsim record; empty: the constant --sim-wrench at 20
  /// °C) and hold their last value after.
  std::vector<std::string> sim_effects;
  std::string sim_profile;
  double sim_span_s = 600.0;
  double sim_speed = 1.0;       ///< paced simulated ADC: simulated seconds per wall-clock second
  bool sim_temperature = true;  ///< false: the simulated ADC reports no temperature
  unsigned rate_hz = 1000;
  std::string cal;    ///< calibration file for slot 0 ("" = built-in)
  std::string cal_b;  ///< calibration file for slot 1 ("" = none)
  /// A slot directory of `ftcal install` (cal_A.json, cal_B.json, active): slots 0/1 from its
  /// files, starting on the one CalSlots::LoadActive resolves ("" = use cal / cal_b).
  std::string cal_dir;
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
  bool health_watch =
      true;  ///< run the health watch (false: --no-health-watch, inputs 100–199 read 0)
  /// Simulated ADC: hold the sampling thread sim_stall_ms on every sim_stall_every-th sample
  /// (0: never) — a deterministic stand-in for a preempted sampler (--sim-stall EVERY:MS).
  unsigned sim_stall_every = 0;
  double sim_stall_ms = 0;
  // Sparkplug B over MQTT (daemon/mqtt_publisher.hpp).
  std::string mqtt;       ///< broker URL mqtt://HOST[:PORT] or mqtts://HOST[:PORT] ("" = none)
  std::string mqtt_ca;    ///< CA certificate file (mqtts)
  std::string mqtt_cert;  ///< client certificate file (mqtts, optional)
  std::string mqtt_key;   ///< its private key file
  std::string mqtt_credentials;  ///< file: user name on line 1, password on line 2 ("" = none)
  std::string sparkplug_group = "ftstack";
  std::string edge_node;     ///< "" = the host name
  std::string device;        ///< "" = the calibration's serial (else "ft-" + its CRC in hex)
  double mqtt_rate_hz = 10;  ///< wrench publications per second (means over each window)
  unsigned mqtt_keepalive_s = 10;
  bool mqtt_write_protect = false;  ///< refuse every command from the broker
  // The web page and JSON API (daemon/http_server.hpp, docs/web.md).
  std::string http;                 ///< HOST:PORT of the web server ("" = none)
  std::string http_credentials;     ///< file: user name on line 1, password on line 2 ("" = open)
  std::string http_cert;            ///< PEM certificate: serve HTTPS (with http_key)
  std::string http_key;             ///< its private key
  bool http_write_protect = false;  ///< refuse every write from the web (page and API)
  // The OPC UA server (daemon/opcua_server.hpp, docs/opcua.md).
  std::string opcua;                     ///< HOST:PORT of the OPC UA server ("" = none)
  std::string opcua_credentials;         ///< file: user name on line 1, password on line 2
  std::string opcua_cert;                ///< server certificate: Basic256Sha256 (with opcua_key)
  std::string opcua_key;                 ///< its private key
  std::vector<std::string> opcua_trust;  ///< client certificates trusted for Basic256Sha256
  bool opcua_write_protect = false;      ///< refuse every method call that changes the sensor
};

/// User name (line 1) and password (line 2) from a file, as --mqtt-credentials and
/// --http-credentials take them; throws FtdError naming `option` and the file.
[[nodiscard]] std::pair<std::string, std::string> ReadCredentialsFile(const std::string& option,
                                                                      const std::string& path);

/// Parses "HOST:PORT"; throws FtdError naming the bad part.
void ParseHostPort(const std::string& text, std::string* host, std::uint16_t* port);

}  // namespace ftstack::daemon
