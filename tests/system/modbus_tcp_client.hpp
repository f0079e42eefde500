// Test helper: a libmodbus TCP client to a local ftd (unit 1, 2 s timeout), closed on destruction.
#pragma once

#include <modbus/modbus.h>

namespace ftstack::test {

class ModbusTcpClient {
 public:
  explicit ModbusTcpClient(int port) {
    ctx_ = modbus_new_tcp("127.0.0.1", port);
    modbus_set_slave(ctx_, 1);
    modbus_set_response_timeout(ctx_, 2, 0);
    connected_ = modbus_connect(ctx_) == 0;
  }
  ~ModbusTcpClient() {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  ModbusTcpClient(const ModbusTcpClient&) = delete;
  ModbusTcpClient& operator=(const ModbusTcpClient&) = delete;
  [[nodiscard]] bool connected() const { return connected_; }
  [[nodiscard]] modbus_t* ctx() { return ctx_; }

 private:
  modbus_t* ctx_ = nullptr;
  bool connected_ = false;
};

}  // namespace ftstack::test
