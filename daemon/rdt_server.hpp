// ATI Net F/T-compatible Raw Data Transfer (RDT) server over UDP, fed by the sampling thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

#include "firmware/device.hpp"
#include "firmware/seqlock.hpp"

namespace ftstack::fw {
class RegisterMap;
}  // namespace ftstack::fw

namespace ftstack::daemon {

/// RDT protocol constants (ATI Net F/T: request 8 bytes, record 36 bytes, all big-endian).
inline constexpr std::uint16_t kRdtHeader = 0x1234;
inline constexpr std::uint16_t kRdtDefaultPort = 49152;
inline constexpr std::size_t kRdtRequestBytes = 8;
inline constexpr std::size_t kRdtRecordBytes = 36;
enum RdtCommand : std::uint16_t {
  kRdtStop = 0x0000,
  kRdtStartRealTime = 0x0002,  ///< one record per packet
  kRdtStartBuffered = 0x0003,  ///< buffer_records records per packet
  kRdtStartMulti = 0x0004,     ///< as buffered (ftd is one unit)
  kRdtResetLatch = 0x0041,     ///< clears peaks and the overload counter (Modbus command 3)
  kRdtSetBias = 0x0042,        ///< tare (Modbus command 1): affects every output, as on an ATI box
};

struct RdtOptions {
  std::string host = "0.0.0.0";
  std::uint16_t port = kRdtDefaultPort;  ///< 0: any free port (see port())
  double counts_per_n = 1e6;             ///< counts per N in the Fx Fy Fz fields
  double counts_per_nm = 1e6;            ///< counts per N·m in the Tx Ty Tz fields
  unsigned buffer_records = 4;           ///< records per packet in buffered / multi-unit mode
  /// Status bits copied into the records' status word (drivers that treat any non-zero status as
  /// a fault may want only the fault bits, e.g. 0x031F without tare 5, temperature 6, simulated 7).
  std::uint32_t status_mask = 0xFFFF;
};

/// Largest number of streaming clients and of records in one packet.
inline constexpr std::size_t kRdtMaxClients = 8;
inline constexpr unsigned kRdtMaxBufferRecords = 40;

/// Live counters (any thread).
struct RdtStats {
  std::uint64_t records_sent = 0;
  std::uint64_t packets_sent = 0;
  std::uint64_t requests = 0;       ///< well-formed requests handled
  std::uint64_t malformed = 0;      ///< requests ignored (size, header, command)
  std::uint64_t refused = 0;        ///< start requests refused: kRdtMaxClients already streaming
  std::uint64_t ring_overruns = 0;  ///< samples the RDT thread fell too far behind to send
  std::uint64_t send_errors = 0;    ///< sendto failures (the packet is dropped, never retried)
  std::uint64_t saturated = 0;      ///< count values clamped to int32
};

/// The server. Publish() is called by the sampling thread (lock-free, never blocks, no heap);
/// Run() is the RDT thread: it answers requests and sends what Publish() queued.
class RdtServer {
 public:
  RdtServer(const RdtOptions& options, fw::RegisterMap* map);
  ~RdtServer();
  RdtServer(const RdtServer&) = delete;
  RdtServer& operator=(const RdtServer&) = delete;

  /// Binds the UDP socket; throws FtdError with the reason on failure.
  void Open();
  [[nodiscard]] std::uint16_t port() const { return port_; }

  /// Queues one published sample (sampling thread only).
  void Publish(const fw::DeviceSample& d);
  /// Serves until `stop` is set.
  void Run(const std::atomic<bool>& stop);
  /// One received datagram from ip:port (network order), as Run handles it; public for the fuzzer.
  void HandleRequest(const std::uint8_t* buf, long n, std::uint32_t ip, std::uint16_t port);
  /// Sends what Publish queued to the streaming clients, as Run does after each wake-up.
  void DrainRing();
  [[nodiscard]] RdtStats stats() const;

 private:
  struct Slot {
    std::uint64_t index = 0;  ///< ring position written (detects overwritten slots)
    std::uint32_t ft_sequence = 0;
    std::uint32_t status = 0;
    fw::WrenchLsb wrench{};
  };
  struct Client {
    std::uint32_t ip = 0;    ///< network order
    std::uint16_t port = 0;  ///< network order
    bool active = false;
    unsigned per_packet = 1;
    std::uint32_t remaining = 0;  ///< records still to send; 0 with infinite = true: no limit
    bool infinite = true;
    std::uint32_t rdt_sequence = 0;
    unsigned pending = 0;
    std::array<std::uint8_t, kRdtMaxBufferRecords * kRdtRecordBytes> packet{};
  };
  static constexpr std::size_t kRingSize = 4096;

  void SendSample(const Slot& s);
  void Flush(Client& c);

  RdtOptions opt_;
  fw::RegisterMap* map_;
  int fd_ = -1;
  std::uint16_t port_ = 0;
  std::array<fw::Seqlock<Slot>, kRingSize> ring_{};
  std::atomic<std::uint64_t> head_{0};
  std::uint64_t tail_ = 0;
  std::array<Client, kRdtMaxClients> clients_{};
  std::atomic<std::uint64_t> records_{0}, packets_{0}, requests_{0}, malformed_{0}, refused_{0},
      overruns_{0}, send_errors_{0}, saturated_{0};
};

}  // namespace ftstack::daemon
