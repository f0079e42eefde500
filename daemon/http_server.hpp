// ftd's web page and JSON API over HTTP(S) (cpp-httplib): reads the register map, writes through
// it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "daemon/options.hpp"
#include "daemon/web_state.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::daemon {

/// API version of the JSON paths (/api/v1/...); docs/web.md.
inline constexpr int kWebApiVersion = 1;
/// Largest request body accepted (a command or a settings object is far smaller): 413 beyond.
inline constexpr std::size_t kWebMaxBodyBytes = 4096;
/// Worker threads of the server. A stream holds one while open; a request holds one only while
/// it is answered (connections are not kept alive: an idle browser tab would hold a thread).
inline constexpr std::size_t kWebThreads = 32;
/// Streams open at once; one more is 503 (threads stay free for requests).
inline constexpr std::uint32_t kWebMaxStreams = 16;
/// Stream rates the API accepts, events per second (default kWebStreamDefaultHz).
inline constexpr int kWebStreamMaxHz = 50;
inline constexpr int kWebStreamDefaultHz = 10;

/// Request counters (any thread).
struct WebStats {
  std::uint64_t requests = 0;      ///< requests answered (any status)
  std::uint64_t errors = 0;        ///< of which 4xx / 5xx
  std::uint64_t writes = 0;        ///< writes accepted into the register map
  std::uint32_t streams_open = 0;  ///< live streams now
};

/// The server. Open() binds (port 0: any free); Run() serves on a pool of worker threads until
/// `stop`. It never touches the sampling thread: reads copy the published sample through
/// RegisterMap::ReadInput (the seqlock), writes go through RegisterMap::WriteHolding with
/// TareSource::kWeb, the path Modbus writes take.
class HttpServer {
 public:
  /// `runtime` gives the live figures the map does not hold (sample rate, clients), as JSON.
  HttpServer(const FtdOptions& options, fw::RegisterMap* map, WebStaticInfo info,
             std::function<nlohmann::json()> runtime);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Reads the credentials and certificate, binds; throws FtdError.
  void Open();
  void Run(const std::atomic<bool>& stop);

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] bool tls() const { return tls_; }
  [[nodiscard]] const std::string& host() const { return host_; }
  [[nodiscard]] WebStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string host_;
  std::uint16_t port_ = 0;
  bool tls_ = false;
};

/// True when this ftd was built with the web server, and with HTTPS.
[[nodiscard]] bool WebServerBuilt();
[[nodiscard]] bool WebHttpsBuilt();

}  // namespace ftstack::daemon
