#include "firmware/modbus_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace ftstack::fw {
namespace {

constexpr int kPollMs = 100;
/// Frames served per connection per poll round, so one flooding client cannot starve the others.
constexpr int kFramesPerRound = 16;

[[nodiscard]] std::uint16_t Be16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

void CountReply(ServerCounters* counters, bool exception) {
  if (counters == nullptr) return;
  counters->requests.fetch_add(1, std::memory_order_relaxed);
  if (exception) counters->exceptions.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

const char* ToString(ServerStatus s) {
  switch (s) {
    case ServerStatus::kOk:
      return "ok";
    case ServerStatus::kBadAddress:
      return "cannot resolve the listening address";
    case ServerStatus::kSocket:
      return "cannot create a socket";
    case ServerStatus::kBind:
      return "cannot bind/listen (address in use or not permitted)";
    case ServerStatus::kSerial:
      return "cannot open or configure the serial device";
    case ServerStatus::kLibmodbus:
      return "libmodbus context allocation failed";
  }
  return "unknown";
}

bool HandleRequest(RegisterMap& map, modbus_t* ctx, modbus_mapping_t* mapping,
                   const std::uint8_t* req, int length, int header_length, bool reply,
                   ServerCounters* counters) {
  // PDU bytes: TCP frames end with the PDU; RTU frames carry a 2-byte CRC after it.
  const int trailer = header_length == static_cast<int>(kMbapLength) ? 0 : 2;
  const int pdu_length = length - header_length - trailer;
  if (pdu_length < 1) return true;  // nothing to answer
  const std::uint8_t* pdu = req + header_length;
  const std::uint8_t function = pdu[0];
  if ((function & 0x80u) != 0) {
    // Codes 128–255 are exception responses, not requests; no exception code can answer them.
    if (counters != nullptr) counters->dropped.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  ModbusException ex = ModbusException::kNone;
  std::array<std::uint16_t, MODBUS_MAX_READ_REGISTERS> values{};
  switch (function) {
    case MODBUS_FC_READ_HOLDING_REGISTERS:
    case MODBUS_FC_READ_INPUT_REGISTERS: {
      if (pdu_length != 5) {
        ex = ModbusException::kIllegalDataValue;
        break;
      }
      const std::uint16_t addr = Be16(pdu + 1);
      const std::uint16_t count = Be16(pdu + 3);
      if (count < 1 || count > MODBUS_MAX_READ_REGISTERS) {
        ex = ModbusException::kIllegalDataValue;
        break;
      }
      if (!reply) return true;  // a broadcast read has no effect
      const bool input = function == MODBUS_FC_READ_INPUT_REGISTERS;
      ex = input ? map.ReadInput(addr, count, values.data())
                 : map.ReadHolding(addr, count, values.data());
      if (ex == ModbusException::kNone) {
        std::uint16_t* tab = input ? mapping->tab_input_registers : mapping->tab_registers;
        std::memcpy(tab + addr, values.data(), count * sizeof(std::uint16_t));
      }
      break;
    }
    case MODBUS_FC_WRITE_SINGLE_REGISTER: {
      if (pdu_length != 5) {
        ex = ModbusException::kIllegalDataValue;
        break;
      }
      const std::uint16_t v = Be16(pdu + 3);
      ex = map.WriteHolding(Be16(pdu + 1), &v, 1);
      break;
    }
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS: {
      if (pdu_length < 6) {
        ex = ModbusException::kIllegalDataValue;
        break;
      }
      const std::uint16_t count = Be16(pdu + 3);
      const int bytes = pdu[5];
      if (count < 1 || count > MODBUS_MAX_WRITE_REGISTERS || bytes != 2 * count ||
          pdu_length != 6 + bytes) {
        ex = ModbusException::kIllegalDataValue;
        break;
      }
      for (std::uint16_t i = 0; i < count; ++i) {
        values[i] = Be16(pdu + 6 + 2 * static_cast<std::size_t>(i));
      }
      ex = map.WriteHolding(Be16(pdu + 1), values.data(), count);
      break;
    }
    default:
      ex = ModbusException::kIllegalFunction;
      break;
  }
  if (!reply) return true;
  CountReply(counters, ex != ModbusException::kNone);
  const int rc = ex == ModbusException::kNone
                     ? modbus_reply(ctx, req, length, mapping)
                     : modbus_reply_exception(ctx, req, static_cast<unsigned>(ex));
  return rc >= 0;
}

// ---------------------------------------------------------------------------------------------
// TCP

ModbusTcpServer::~ModbusTcpServer() {
  for (Connection& c : conns_) Close(c);
  if (listen_fd_ >= 0) ::close(listen_fd_);
  if (ctx_ != nullptr) {
    modbus_set_socket(ctx_, -1);
    modbus_free(ctx_);
  }
  if (mapping_ != nullptr) modbus_mapping_free(mapping_);
}

ServerStatus ModbusTcpServer::Open(const char* host, std::uint16_t port, std::uint8_t unit_id) {
  unit_id_ = unit_id;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* res = nullptr;
  if (getaddrinfo(host, nullptr, &hints, &res) != 0 || res == nullptr) {
    return ServerStatus::kBadAddress;
  }
  sockaddr_in addr{};
  std::memcpy(&addr, res->ai_addr, sizeof(addr));
  freeaddrinfo(res);
  addr.sin_port = htons(port);
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return ServerStatus::kSocket;
  const int one = 1;
  (void)setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listen_fd_, 64) != 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    return ServerStatus::kBind;
  }
  socklen_t len = sizeof(addr);
  if (getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port_ = ntohs(addr.sin_port);
  }
  // The context only frames replies on the client sockets handed to it; it never connects.
  ctx_ = modbus_new_tcp("127.0.0.1", MODBUS_TCP_DEFAULT_PORT);
  mapping_ = modbus_mapping_new(0, 0, kHoldingRegisterSpan, kInputAddressSpan);
  if (ctx_ == nullptr || mapping_ == nullptr) return ServerStatus::kLibmodbus;
  (void)modbus_set_response_timeout(ctx_, 0, 1);  // no sleep on libmodbus's own error paths
  return ServerStatus::kOk;
}

void ModbusTcpServer::Close(Connection& c) {
  if (c.fd >= 0) ::close(c.fd);
  c.fd = -1;
  c.frames.Reset();
}

void ModbusTcpServer::Accept() {
  for (;;) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;
    const int one = 1;
    (void)setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    // A free slot, else evict in this order: a client stuck mid-frame, a client that never
    // completed a request, the client silent longest.
    Connection* slot = nullptr;
    auto rank = [](const Connection& c) { return c.frames.fill() > 0 ? 0 : (c.served ? 2 : 1); };
    for (Connection& c : conns_) {
      if (c.fd < 0) {
        slot = &c;
        break;
      }
      if (slot == nullptr || rank(c) < rank(*slot) ||
          (rank(c) == rank(*slot) && c.last_active_us < slot->last_active_us)) {
        slot = &c;
      }
    }
    if (slot == nullptr) {  // no connection slots at all (cannot happen with kMaxConnections > 0)
      ::close(fd);
      return;
    }
    if (slot->fd >= 0) {  // full: the longest-silent client makes room
      Close(*slot);
      counters_.dropped.fetch_add(1, std::memory_order_relaxed);
    }
    slot->fd = fd;
    slot->frames.Reset();
    slot->served = false;
    slot->last_active_us = MonotonicUs();
    counters_.connections.fetch_add(1, std::memory_order_relaxed);
  }
}

bool ModbusTcpServer::Service(Connection& c) {
  int frames = 0;
  for (;;) {
    // Serve every complete frame in the buffer.
    for (FrameState st = c.frames.Next(); st != FrameState::kNeedMore; st = c.frames.Next()) {
      if (st == FrameState::kBadHeader) {
        counters_.dropped.fetch_add(1, std::memory_order_relaxed);
        return false;  // not Modbus/TCP: the stream cannot be resynchronised
      }
      const std::uint8_t unit = c.frames.unit();
      if (unit == unit_id_ || unit == kTcpWildcardUnit) {
        modbus_set_socket(ctx_, c.fd);
        const bool ok = HandleRequest(map_, ctx_, mapping_, c.frames.frame(),
                                      static_cast<int>(c.frames.frame_length()),
                                      static_cast<int>(kMbapLength), true, &counters_);
        modbus_set_socket(ctx_, -1);
        if (!ok) return false;
        c.served = true;
      } else {
        counters_.ignored.fetch_add(1, std::memory_order_relaxed);
      }
      c.frames.Pop();
      if (++frames >= kFramesPerRound) return true;
    }
    const ssize_t n = ::recv(c.fd, c.frames.space(), c.frames.space_size(), 0);
    if (n > 0) {
      (void)c.frames.Commit(static_cast<std::size_t>(n));
      c.last_active_us = MonotonicUs();
      continue;
    }
    if (n == 0) return false;  // peer closed (possibly mid-frame: the partial frame is dropped)
    if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
    if (errno == EINTR) continue;
    return false;
  }
}

bool ModbusTcpServer::FramePending(const Connection& c) {
  // A complete frame (or a header to refuse) already buffered: no new data will announce it.
  return c.fd >= 0 && c.frames.Pending();
}

void ModbusTcpServer::Run(const std::atomic<bool>& stop) {
  std::array<pollfd, kMaxTcpClients + 1> fds{};
  std::array<Connection*, kMaxTcpClients + 1> owner{};
  while (!stop.load(std::memory_order_relaxed)) {
    std::size_t n = 0;
    bool pending = false;
    fds[n] = pollfd{listen_fd_, POLLIN, 0};
    owner[n++] = nullptr;
    for (Connection& c : conns_) {
      if (c.fd < 0) continue;
      fds[n] = pollfd{c.fd, POLLIN, 0};
      owner[n++] = &c;
      pending = pending || FramePending(c);
    }
    const int rc = ::poll(fds.data(), n, pending ? 0 : kPollMs);
    if (rc < 0) continue;
    for (std::size_t i = 1; i < n; ++i) {
      if (fds[i].revents == 0 && !FramePending(*owner[i])) continue;
      if (!Service(*owner[i])) Close(*owner[i]);
    }
    if ((fds[0].revents & POLLIN) != 0) Accept();
  }
}

// ---------------------------------------------------------------------------------------------
// RTU

ModbusRtuServer::~ModbusRtuServer() {
  if (ctx_ != nullptr) {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  if (mapping_ != nullptr) modbus_mapping_free(mapping_);
}

ServerStatus ModbusRtuServer::Open(const char* device, int baud, char parity,
                                   std::uint8_t unit_id) {
  ctx_ = modbus_new_rtu(device, baud, parity, 8, 1);
  mapping_ = modbus_mapping_new(0, 0, kHoldingRegisterSpan, kInputAddressSpan);
  if (ctx_ == nullptr || mapping_ == nullptr) return ServerStatus::kLibmodbus;
  if (modbus_set_slave(ctx_, unit_id) != 0 || modbus_connect(ctx_) != 0) {
    modbus_free(ctx_);
    ctx_ = nullptr;
    return ServerStatus::kSerial;
  }
  (void)modbus_set_response_timeout(ctx_, 0, 1);
  (void)modbus_set_byte_timeout(ctx_, 0, 100000);  // a frame that stops for 0.1 s is dropped
  return ServerStatus::kOk;
}

void ModbusRtuServer::Run(const std::atomic<bool>& stop) {
  std::array<std::uint8_t, MODBUS_RTU_MAX_ADU_LENGTH> buf{};
  const int fd = modbus_get_socket(ctx_);
  while (!stop.load(std::memory_order_relaxed)) {
    pollfd p{fd, POLLIN, 0};
    const int rc = ::poll(&p, 1, kPollMs);
    if (rc <= 0) continue;
    if ((p.revents & POLLIN) == 0) {  // hang-up or error without data: do not spin
      ::poll(nullptr, 0, kPollMs);
      continue;
    }
    const int len = modbus_receive(ctx_, buf.data());
    if (len < 0) {  // CRC error, timeout mid-frame, garbage: drop what is pending
      counters_.dropped.fetch_add(1, std::memory_order_relaxed);
      (void)modbus_flush(ctx_);
      continue;
    }
    if (len == 0) {
      counters_.ignored.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    const bool broadcast = buf[0] == MODBUS_BROADCAST_ADDRESS;
    (void)HandleRequest(map_, ctx_, mapping_, buf.data(), len, 1, !broadcast, &counters_);
  }
}

}  // namespace ftstack::fw
