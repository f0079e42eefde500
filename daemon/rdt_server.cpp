#include "daemon/rdt_server.hpp"

#include "daemon/options.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>

#include "firmware/register_map.hpp"

namespace ftstack::daemon {
namespace {

void PutU32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

std::uint16_t GetU16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}
std::uint32_t GetU32(const std::uint8_t* p) {
  return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
         (static_cast<std::uint32_t>(p[2]) << 8) | p[3];
}

}  // namespace

RdtServer::RdtServer(const RdtOptions& options, fw::RegisterMap* map) : opt_(options), map_(map) {
  if (opt_.buffer_records < 1) opt_.buffer_records = 1;
  if (opt_.buffer_records > kRdtMaxBufferRecords) opt_.buffer_records = kRdtMaxBufferRecords;
}

RdtServer::~RdtServer() {
  if (fd_ >= 0) ::close(fd_);
}

void RdtServer::Open() {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw FtdError(std::string("socket: ") + std::strerror(errno));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(opt_.port);
  if (::inet_pton(AF_INET, opt_.host.c_str(), &a.sin_addr) != 1) {
    throw FtdError("'" + opt_.host + "' is not an IPv4 address");
  }
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    throw FtdError(std::string("bind: ") + std::strerror(errno));
  }
  socklen_t len = sizeof a;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0) port_ = ntohs(a.sin_port);
  const int sndbuf = 1 << 20;
  (void)::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
}

void RdtServer::Publish(const fw::DeviceSample& d) {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  Slot s;
  s.index = head;
  s.ft_sequence = d.sample.sequence;
  s.status = d.sample.status;
  s.wrench = d.sample.wrench;
  ring_[head % kRingSize].Write(s);
  head_.store(head + 1, std::memory_order_release);
}

RdtStats RdtServer::stats() const {
  RdtStats s;
  s.records_sent = records_.load(std::memory_order_relaxed);
  s.packets_sent = packets_.load(std::memory_order_relaxed);
  s.requests = requests_.load(std::memory_order_relaxed);
  s.malformed = malformed_.load(std::memory_order_relaxed);
  s.refused = refused_.load(std::memory_order_relaxed);
  s.ring_overruns = overruns_.load(std::memory_order_relaxed);
  s.send_errors = send_errors_.load(std::memory_order_relaxed);
  s.saturated = saturated_.load(std::memory_order_relaxed);
  return s;
}

void RdtServer::HandleRequest(const std::uint8_t* buf, long n, std::uint32_t ip,
                              std::uint16_t port) {
  if (n != static_cast<long>(kRdtRequestBytes) || GetU16(buf) != kRdtHeader) {
    malformed_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const std::uint16_t cmd = GetU16(buf + 2);
  const std::uint32_t count = GetU32(buf + 4);
  Client* known = nullptr;
  Client* free_slot = nullptr;
  for (Client& c : clients_) {
    if (c.active && c.ip == ip && c.port == port) known = &c;
    if (!c.active && free_slot == nullptr) free_slot = &c;
  }
  switch (cmd) {
    case kRdtStop:
      if (known != nullptr) {
        Flush(*known);
        known->active = false;
      }
      break;
    case kRdtStartRealTime:
    case kRdtStartBuffered:
    case kRdtStartMulti: {
      Client* c = known != nullptr ? known : free_slot;
      if (c == nullptr) {
        refused_.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      *c = Client{};
      c->ip = ip;
      c->port = port;
      c->active = true;
      c->per_packet = cmd == kRdtStartRealTime ? 1u : opt_.buffer_records;
      c->infinite = count == 0;
      c->remaining = count;
      break;
    }
    case kRdtResetLatch:
    case kRdtSetBias: {
      const std::uint16_t v = cmd == kRdtSetBias ? fw::kCmdTare : fw::kCmdClearPeaks;
      if (map_ != nullptr) (void)map_->WriteHolding(fw::kHoldCommand, &v, 1, fw::TareSource::kRdt);
      break;
    }
    default:
      malformed_.fetch_add(1, std::memory_order_relaxed);
      return;
  }
  requests_.fetch_add(1, std::memory_order_relaxed);
}

void RdtServer::Flush(Client& c) {
  if (c.pending == 0) return;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = c.ip;
  to.sin_port = c.port;
  const std::size_t bytes = c.pending * kRdtRecordBytes;
  const ssize_t w = ::sendto(fd_, c.packet.data(), bytes, MSG_DONTWAIT,
                             reinterpret_cast<const sockaddr*>(&to), sizeof to);
  if (w == static_cast<ssize_t>(bytes)) {
    packets_.fetch_add(1, std::memory_order_relaxed);
    records_.fetch_add(c.pending, std::memory_order_relaxed);
  } else {
    send_errors_.fetch_add(1, std::memory_order_relaxed);
  }
  c.pending = 0;
}

void RdtServer::SendSample(const Slot& s) {
  std::int32_t counts[fw::kAxes];
  for (std::size_t a = 0; a < fw::kAxes; ++a) {
    const double per_unit = a < 3 ? opt_.counts_per_n : opt_.counts_per_nm;
    const double v = std::round(static_cast<double>(s.wrench[a]) * fw::AxisLsb(a) * per_unit);
    constexpr double kMax = std::numeric_limits<std::int32_t>::max();
    if (std::fabs(v) > kMax) saturated_.fetch_add(1, std::memory_order_relaxed);
    counts[a] = static_cast<std::int32_t>(v > kMax ? kMax : (v < -kMax ? -kMax : v));
  }
  for (Client& c : clients_) {
    if (!c.active) continue;
    std::uint8_t* r = &c.packet[c.pending * kRdtRecordBytes];
    PutU32(r, ++c.rdt_sequence);
    PutU32(r + 4, s.ft_sequence);
    PutU32(r + 8, s.status & opt_.status_mask);
    for (std::size_t a = 0; a < fw::kAxes; ++a) {
      PutU32(r + 12 + 4 * a, static_cast<std::uint32_t>(counts[a]));
    }
    ++c.pending;
    const bool last = !c.infinite && --c.remaining == 0;
    if (c.pending >= c.per_packet || last) Flush(c);
    if (last) c.active = false;
  }
}

void RdtServer::DrainRing() {
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  if (head - tail_ > kRingSize - 1) {  // fell a whole ring behind: skip to what is still there
    overruns_.fetch_add(head - tail_ - (kRingSize - 1), std::memory_order_relaxed);
    tail_ = head - (kRingSize - 1);
  }
  for (; tail_ != head; ++tail_) {
    Slot s;
    if (!ring_[tail_ % kRingSize].Read(&s) || s.index != tail_) {
      overruns_.fetch_add(1, std::memory_order_relaxed);  // overwritten while we looked
      continue;
    }
    SendSample(s);
  }
}

void RdtServer::Run(const std::atomic<bool>& stop) {
  tail_ = head_.load(std::memory_order_acquire);  // stream from now on
  std::uint8_t buf[512];
  pollfd p{fd_, POLLIN, 0};
  const timespec wait{0, 200000};  // 0.2 ms: the latency the sampling thread's ring adds at most
  while (!stop.load(std::memory_order_relaxed)) {
    (void)::ppoll(&p, 1, &wait, nullptr);
    for (;;) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n =
          ::recvfrom(fd_, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) break;
      HandleRequest(buf, n, from.sin_addr.s_addr, from.sin_port);
    }
    DrainRing();
  }
}

}  // namespace ftstack::daemon
