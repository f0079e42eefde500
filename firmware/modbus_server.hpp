// Modbus TCP (many clients, one poll loop) and RTU (serial) slaves over libmodbus for a
// RegisterMap.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include <modbus/modbus.h>

#include "firmware/register_map.hpp"
#include "firmware/tcp_frame.hpp"

namespace ftstack::fw {

/// Largest number of simultaneous TCP clients. When all are taken, a new connection replaces the
/// one stuck longest mid-frame, else one that never completed a request, else the one silent
/// longest (so stalled or abandoned clients cannot lock working ones out).
inline constexpr std::size_t kMaxTcpClients = 32;
/// Unit id a TCP slave answers besides its own.
inline constexpr std::uint8_t kTcpWildcardUnit = 255;

/// Why a server could not start.
enum class ServerStatus : std::uint8_t {
  kOk = 0,
  kBadAddress,
  kSocket,
  kBind,
  kSerial,
  kLibmodbus
};
[[nodiscard]] const char* ToString(ServerStatus s);

/// What a server has done (read from any thread).
struct ServerCounters {
  std::atomic<std::uint64_t> requests{0};     ///< requests answered (normal or exception)
  std::atomic<std::uint64_t> exceptions{0};   ///< of which exception replies
  std::atomic<std::uint64_t> dropped{0};      ///< malformed frames dropped / connections closed
  std::atomic<std::uint64_t> ignored{0};      ///< requests for another unit id
  std::atomic<std::uint64_t> connections{0};  ///< TCP connections accepted
};

/// Decodes one request PDU (function code first) addressed to this slave, runs it on `map` and
/// sends the reply through libmodbus (`req` is the whole ADU, `header_length` bytes before the
/// function code). Quantities outside the Modbus limits or a PDU of the wrong length give 03,
/// functions other than 03, 04, 06, 16 give 01; a function code of 128 or more (the exception
/// range) is dropped without reply. `reply` false (RTU broadcast) executes writes silently.
/// Returns false when sending failed.
[[nodiscard]] bool HandleRequest(RegisterMap& map, modbus_t* ctx, modbus_mapping_t* mapping,
                                 const std::uint8_t* req, int length, int header_length, bool reply,
                                 ServerCounters* counters);

/// Modbus TCP slave. Frames are assembled per connection from non-blocking reads, so a client
/// that stops mid-frame or sends garbage never blocks the others: a bad MBAP header (protocol id ≠
/// 0, length outside 2 … 254) closes that connection; a bad PDU gets an exception.
class ModbusTcpServer {
 public:
  explicit ModbusTcpServer(RegisterMap& map) : map_(map) {}
  ~ModbusTcpServer();
  ModbusTcpServer(const ModbusTcpServer&) = delete;
  ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

  /// Binds and listens on host:port (IPv4 dotted or a name; port 0 picks a free port).
  [[nodiscard]] ServerStatus Open(const char* host, std::uint16_t port, std::uint8_t unit_id);
  /// The port actually bound (after Open).
  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// Serves until `stop` becomes true (checked at least every 100 ms).
  void Run(const std::atomic<bool>& stop);
  [[nodiscard]] const ServerCounters& counters() const { return counters_; }

 private:
  struct Connection {
    int fd = -1;
    std::uint64_t last_active_us = 0;  ///< when it last sent something (or connected)
    bool served = false;               ///< completed at least one request
    TcpFrameAssembler frames;
  };
  void Accept();
  /// Reads what is available and serves every complete frame; false when the connection must go.
  [[nodiscard]] bool Service(Connection& c);
  void Close(Connection& c);
  [[nodiscard]] static bool FramePending(const Connection& c);

  RegisterMap& map_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::uint8_t unit_id_ = 1;
  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  std::array<Connection, kMaxTcpClients> conns_{};
  ServerCounters counters_{};
};

/// Modbus RTU slave on a serial device (8 data bits, 1 stop bit).
class ModbusRtuServer {
 public:
  explicit ModbusRtuServer(RegisterMap& map) : map_(map) {}
  ~ModbusRtuServer();
  ModbusRtuServer(const ModbusRtuServer&) = delete;
  ModbusRtuServer& operator=(const ModbusRtuServer&) = delete;

  /// Opens `device` at `baud` with parity 'N', 'E' or 'O'.
  [[nodiscard]] ServerStatus Open(const char* device, int baud, char parity, std::uint8_t unit_id);
  /// Serves until `stop` becomes true (checked at least every 100 ms).
  void Run(const std::atomic<bool>& stop);
  [[nodiscard]] const ServerCounters& counters() const { return counters_; }

 private:
  RegisterMap& map_;
  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  ServerCounters counters_{};
};

}  // namespace ftstack::fw
