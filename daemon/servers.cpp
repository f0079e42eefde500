#include "daemon/servers.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace ftstack::daemon {

void Servers::Open(const FtdOptions& opt, fw::RegisterMap& map) {
  if (!opt.modbus_tcp.empty()) {
    std::string host;
    std::uint16_t port = 0;
    ParseHostPort(opt.modbus_tcp, &host, &port);
    tcp_ = std::make_unique<fw::ModbusTcpServer>(map);
    const fw::ServerStatus s =
        tcp_->Open(host.c_str(), port, static_cast<std::uint8_t>(opt.unit_id));
    if (s != fw::ServerStatus::kOk) {
      throw FtdError("Modbus TCP on " + opt.modbus_tcp + ": " + fw::ToString(s));
    }
  }
  if (!opt.modbus_rtu.empty()) {
    rtu_ = std::make_unique<fw::ModbusRtuServer>(map);
    const fw::ServerStatus s = rtu_->Open(opt.modbus_rtu.c_str(), static_cast<int>(opt.baud),
                                          opt.parity, static_cast<std::uint8_t>(opt.unit_id));
    if (s != fw::ServerStatus::kOk) {
      throw FtdError("Modbus RTU on " + opt.modbus_rtu + ": " + fw::ToString(s) + " (" +
                     std::system_category().message(errno) + ")");
    }
  }
  if (!opt.rdt.empty()) OpenRdt(opt, map);
}

void Servers::OpenRdt(const FtdOptions& opt, fw::RegisterMap& map) {
  RdtOptions ro;
  try {
    ParseHostPort(opt.rdt, &ro.host, &ro.port);
  } catch (const FtdError& e) {  // its message names --modbus-tcp
    const std::string m = e.what();
    throw FtdError("--rdt" + m.substr(m.find(' ')));
  }
  if (!(opt.rdt_counts_per_n > 0) || !(opt.rdt_counts_per_nm > 0) ||
      !std::isfinite(opt.rdt_counts_per_n) || !std::isfinite(opt.rdt_counts_per_nm)) {
    throw FtdError("--rdt-counts-per-n and --rdt-counts-per-nm must be positive");
  }
  ro.counts_per_n = opt.rdt_counts_per_n;
  ro.counts_per_nm = opt.rdt_counts_per_nm;
  ro.buffer_records = opt.rdt_buffer;
  ro.status_mask = opt.rdt_status_mask;
  rdt_ = std::make_unique<RdtServer>(ro, &map);
  try {
    rdt_->Open();
  } catch (const FtdError& e) {
    throw FtdError("RDT on " + opt.rdt + ": " + e.what());
  }
  std::fprintf(stderr, "ftd: serving RDT on %s:%u (%g counts/N, %g counts/N·m)\n", ro.host.c_str(),
               static_cast<unsigned>(rdt_->port()), ro.counts_per_n, ro.counts_per_nm);
}

void Servers::Spawn(std::vector<std::thread>* threads, const std::atomic<bool>& stop) {
  if (tcp_) threads->emplace_back([this, &stop] { tcp_->Run(stop); });
  if (rtu_) threads->emplace_back([this, &stop] { rtu_->Run(stop); });
  if (rdt_) threads->emplace_back([this, &stop] { rdt_->Run(stop); });
}

}  // namespace ftstack::daemon
