// ftd's OPC UA server (open62541): the register map as an address space a PLC or SCADA browses.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/options.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::daemon {

/// Namespace URI of ftd's own nodes (namespace index 1 of the server).
inline constexpr const char* kOpcuaNamespace = "urn:ftstack:ftd";
/// Namespace URI of OPC UA for Devices (DI): the device object's properties carry its browse names.
inline constexpr const char* kOpcuaDiNamespace = "http://opcfoundation.org/UA/DI/";
/// Fastest sampling and publishing interval a client may ask for, ms.
inline constexpr double kOpcuaMinIntervalMs = 10.0;
/// Sessions open at once; one more is refused (the server thread stays responsive).
inline constexpr std::uint16_t kOpcuaMaxSessions = 64;

/// What the device object shows and does not change while ftd runs.
struct OpcuaDeviceInfo {
  std::array<double, 6> rated{};  ///< N and N·m per axis: the EURange (0: no rating, ±inf)
  std::string serial;             ///< the active calibration's serial
  std::string cal_date;           ///< the active calibration's date
  std::uint32_t cal_crc = 0;      ///< its CRC-32: the calibration revision
  std::string adc;                ///< sim, hx711, spi
  unsigned rate_hz = 0;
};

/// Sessions and method calls so far (any thread).
struct OpcuaStats {
  std::uint64_t method_calls = 0;    ///< calls answered (any status)
  std::uint64_t method_refused = 0;  ///< of which refused (write protection, bad argument)
};

/// The server. Open() builds the address space and binds; Run() serves on the calling thread
/// until `stop`. Values are read through RegisterMap::ReadInput (the seqlock copy of the published
/// sample, never blocking the sampler); methods write through RegisterMap::WriteHolding with
/// TareSource::kOpcua, the path Modbus writes take.
class OpcuaServer {
 public:
  OpcuaServer(const FtdOptions& options, fw::RegisterMap* map, OpcuaDeviceInfo info);
  ~OpcuaServer();
  OpcuaServer(const OpcuaServer&) = delete;
  OpcuaServer& operator=(const OpcuaServer&) = delete;

  /// Reads credentials, certificate, key and trust list, builds the address space, binds;
  /// throws FtdError naming what failed.
  void Open();
  void Run(const std::atomic<bool>& stop);

  [[nodiscard]] const std::string& host() const { return host_; }
  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] bool secure() const { return secure_; }
  [[nodiscard]] OpcuaStats stats() const;

  /// The server's state (daemon/opcua_impl.hpp): public so open62541's C callbacks reach it.
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  std::string host_;
  std::uint16_t port_ = 0;
  bool secure_ = false;
};

}  // namespace ftstack::daemon
