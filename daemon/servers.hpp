// ftd's servers over one register map: Modbus TCP, Modbus RTU and ATI Net F/T RDT.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "daemon/options.hpp"
#include "daemon/rdt_server.hpp"
#include "firmware/modbus_server.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::daemon {

/// The servers the options ask for; each runs on its own thread until stopped.
class Servers {
 public:
  /// Opens the Modbus TCP, Modbus RTU and RDT servers asked for; throws FtdError naming the one
  /// that could not open.
  void Open(const FtdOptions& opt, fw::RegisterMap& map);
  /// Starts one thread per open server, each running until `stop`.
  void Spawn(std::vector<std::thread>* threads, const std::atomic<bool>& stop);

  [[nodiscard]] std::uint16_t tcp_port() const { return tcp_ ? tcp_->port() : 0; }
  [[nodiscard]] const fw::ServerCounters* tcp_counters() const {
    return tcp_ ? &tcp_->counters() : nullptr;
  }
  /// The RDT server (nullptr without --rdt); the sampling thread publishes into it.
  [[nodiscard]] RdtServer* rdt() const { return rdt_.get(); }

 private:
  void OpenRdt(const FtdOptions& opt, fw::RegisterMap& map);

  std::unique_ptr<fw::ModbusTcpServer> tcp_;
  std::unique_ptr<fw::ModbusRtuServer> rtu_;
  std::unique_ptr<RdtServer> rdt_;
};

}  // namespace ftstack::daemon
