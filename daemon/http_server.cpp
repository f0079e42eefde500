#include "daemon/http_server.hpp"

#include <httplib.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "daemon/web_assets.hpp"
#include "firmware/health_registers.hpp"
#include "firmware/health_types.hpp"
#include "firmware/status_bits.hpp"

namespace ftstack::daemon {

namespace {

constexpr const char* kAxes[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
constexpr const char* kUnits[6] = {"N", "N", "N", "N·m", "N·m", "N·m"};

/// Decodes standard base64 (RFC 4648); false on a character outside the alphabet.
bool DecodeBase64(const std::string& text, std::string* out) {
  out->clear();
  std::uint32_t acc = 0;
  int bits = 0;
  for (const char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z') {
      v = c - 'A';
    } else if (c >= 'a' && c <= 'z') {
      v = c - 'a' + 26;
    } else if (c >= '0' && c <= '9') {
      v = c - '0' + 52;
    } else if (c == '+') {
      v = 62;
    } else if (c == '/') {
      v = 63;
    } else if (c == '=') {
      break;
    } else {
      return false;
    }
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out->push_back(static_cast<char>((acc >> bits) & 0xFFu));
    }
  }
  return true;
}

/// Compares without stopping at the first difference (no timing hint at the password).
bool SameSecret(const std::string& a, const std::string& b) {
  unsigned diff = a.size() == b.size() ? 0u : 1u;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned>(a[i] ^ (i < b.size() ? b[i] : 0));
  }
  return diff == 0;
}

void SendJson(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}
void SendError(httplib::Response& res, int status, const std::string& message) {
  SendJson(res, status, {{"error", message}});
}

const char* ExceptionWords(fw::ModbusException e) {
  switch (e) {
    case fw::ModbusException::kNone:
      return "ok";
    case fw::ModbusException::kIllegalFunction:
      return "illegal function";
    case fw::ModbusException::kIllegalDataAddress:
      return "illegal data address";
    case fw::ModbusException::kIllegalDataValue:
      return "value out of range, or a protected register while locked";
    case fw::ModbusException::kDeviceFailure:
      return "device failure (no sample could be read)";
  }
  return "unknown";
}

/// Paths and the one method each answers; anything else on them is 405.
struct Route {
  const char* path;
  const char* method;
};
constexpr Route kRoutes[] = {
    {"/", "GET"},
    {"/index.html", "GET"},
    {"/app.js", "GET"},
    {"/style.css", "GET"},
    {"/uPlot.iife.min.js", "GET"},
    {"/uPlot.min.css", "GET"},
    {"/api/v1", "GET"},
    {"/api/v1/info", "GET"},
    {"/api/v1/state", "GET"},
    {"/api/v1/wrench", "GET"},
    {"/api/v1/runtime", "GET"},
    {"/api/v1/stream", "GET"},
    {"/api/v1/command", "POST"},
    {"/api/v1/settings", "POST"},
};

}  // namespace

struct HttpServer::Impl {
  FtdOptions opt;
  fw::RegisterMap* map;
  WebStaticInfo info;
  std::function<nlohmann::json()> runtime;
  std::unique_ptr<httplib::Server> server;
  std::string user, password;
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> requests{0}, errors{0}, writes{0};
  std::atomic<std::uint32_t> streams{0};

  /// The whole input table and the holding registers; false when no sample could be read.
  bool ReadMap(std::vector<std::uint16_t>* in, std::vector<std::uint16_t>* hold) {
    in->assign(fw::kInputAddressSpan, 0);
    if (map->ReadInput(0, fw::kInputAddressSpan, in->data()) != fw::ModbusException::kNone) {
      return false;
    }
    if (hold != nullptr) {
      hold->assign(fw::kHoldingRegisterSpan, 0);
      if (map->ReadHolding(0, fw::kHoldingRegisterSpan, hold->data()) !=
          fw::ModbusException::kNone) {
        return false;
      }
    }
    return true;
  }

  nlohmann::json Info() const {
    nlohmann::json rated = nlohmann::json::array();
    nlohmann::json limit = nlohmann::json::array();
    bool any = false;
    for (const double r : info.rated) any = any || r > 0;
    for (const double r : info.rated) {
      rated.push_back(any ? nlohmann::json(r) : nlohmann::json(nullptr));
      // The overload rule flags a combined load above 105 % of rated (status bit 1).
      limit.push_back(any ? nlohmann::json(1.05 * r) : nlohmann::json(nullptr));
    }
    nlohmann::json slots = nlohmann::json::array();
    for (const WebCalLabel& l : info.slots) {
      slots.push_back(l.present
                          ? nlohmann::json{{"serial", l.serial}, {"date", l.date}, {"file", l.file}}
                          : nlohmann::json(nullptr));
    }
    return {{"api_version", kWebApiVersion},
            {"axes", kAxes},
            {"units", kUnits},
            {"rated_n_nm", rated},
            {"overload_limit_n_nm", limit},
            {"calibration_slots", slots},
            {"rate_hz", info.rate_hz},
            {"adc", info.adc},
            {"write_protected", opt.http_write_protect},
            {"stream_max_hz", kWebStreamMaxHz}};
  }

  /// One write through the register map, as a Modbus master's; the reply says what happened.
  bool Write(httplib::Response& res, std::uint16_t addr, const std::vector<std::uint16_t>& values,
             const std::string& what) {
    const fw::ModbusException e = map->WriteHolding(
        addr, values.data(), static_cast<std::uint16_t>(values.size()), fw::TareSource::kWeb);
    if (e != fw::ModbusException::kNone) {
      SendError(res, 422, what + " refused: " + ExceptionWords(e));
      return false;
    }
    writes.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  void Command(const httplib::Request& req, httplib::Response& res) {
    if (opt.http_write_protect) {
      SendError(res, 403, "write-protected: ftd runs with --http-write-protect; nothing changed");
      return;
    }
    const nlohmann::json j = nlohmann::json::parse(req.body, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("command") || !j["command"].is_string()) {
      SendError(res, 400, "expected a JSON object {\"command\": NAME}");
      return;
    }
    const std::string c = j["command"].get<std::string>();
    struct Cmd {
      const char* name;
      std::uint16_t addr;
      std::uint16_t value;
    };
    static constexpr Cmd kCmds[] = {
        {"tare", fw::kHoldCommand, fw::kCmdTare},
        {"clear_tare", fw::kHoldCommand, fw::kCmdClearTare},
        {"clear_peaks", fw::kHoldCommand, fw::kCmdClearPeaks},
        {"clear_findings", fw::kHoldHealthCommand, fw::kHealthCmdClear},
        {"commission", fw::kHoldHealthCommand, fw::kHealthCmdCommission},
    };
    for (const Cmd& k : kCmds) {
      if (c == k.name) {
        if (Write(res, k.addr, {k.value}, c)) SendJson(res, 200, {{"ok", true}, {"command", c}});
        return;
      }
    }
    SendError(
        res, 400,
        "unknown command '" + c + "' (tare, clear_tare, clear_peaks, clear_findings, commission)");
  }

  /// Settings: each given key is one register write; all are checked before any is written.
  void Settings(const httplib::Request& req, httplib::Response& res) {
    if (opt.http_write_protect) {
      SendError(res, 403, "write-protected: ftd runs with --http-write-protect; nothing changed");
      return;
    }
    const nlohmann::json j = nlohmann::json::parse(req.body, nullptr, false);
    if (j.is_discarded() || !j.is_object() || j.empty()) {
      SendError(res, 400, "expected a JSON object of settings");
      return;
    }
    std::vector<std::pair<std::uint16_t, std::vector<std::uint16_t>>> writes_asked;
    const auto uint_of = [&](const std::string& key, std::uint16_t* v) {
      const nlohmann::json& x = j[key];
      if (!x.is_number_unsigned() || x.get<std::uint64_t>() > 0xFFFF) {
        SendError(res, 400, "'" + key + "' must be an integer 0 … 65535");
        return false;
      }
      *v = static_cast<std::uint16_t>(x.get<std::uint64_t>());
      return true;
    };
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& key = it.key();
      std::uint16_t v = 0;
      if (key == "filter_length" || key == "decimation") {
        if (!uint_of(key, &v)) return;
        writes_asked.push_back(
            {key == "filter_length" ? fw::kHoldFilterLength : fw::kHoldDecimation, {v}});
      } else if (key == "cal_slot") {
        if (!uint_of(key, &v)) return;
        // Protected, as for a Modbus master: the unlock key first, then the slot.
        writes_asked.push_back({fw::kHoldUnlock, {fw::kUnlockKey}});
        writes_asked.push_back({fw::kHoldCalSlot, {v}});
      } else if (key == "health_thresholds_51_59") {
        const nlohmann::json& x = *it;
        if (!x.is_array() ||
            x.size() != fw::kHoldHealthLastThreshold - fw::kHoldHealthFirstThreshold + 1) {
          SendError(res, 400, "'health_thresholds_51_59' must be an array of 9 integers");
          return;
        }
        std::vector<std::uint16_t> vals;
        for (const auto& e : x) {
          if (!e.is_number_unsigned() || e.get<std::uint64_t>() > 0xFFFF) {
            SendError(res, 400, "'health_thresholds_51_59' must hold integers 0 … 65535");
            return;
          }
          vals.push_back(static_cast<std::uint16_t>(e.get<std::uint64_t>()));
        }
        writes_asked.push_back({fw::kHoldHealthFirstThreshold, vals});
      } else {
        SendError(res, 400,
                  "unknown setting '" + key +
                      "' (filter_length, decimation, cal_slot, health_thresholds_51_59)");
        return;
      }
    }
    for (const auto& [addr, vals] : writes_asked) {
      if (!Write(res, addr, vals, "register " + std::to_string(addr))) return;
    }
    SendJson(res, 200, {{"ok", true}});
  }

  bool Authorized(const httplib::Request& req) const {
    if (user.empty()) return true;
    const std::string h = req.get_header_value("Authorization");
    if (h.rfind("Basic ", 0) != 0) return false;
    std::string decoded;
    if (!DecodeBase64(h.substr(6), &decoded)) return false;
    const std::size_t colon = decoded.find(':');
    if (colon == std::string::npos) return false;
    const bool u = SameSecret(decoded.substr(0, colon), user);
    const bool p = SameSecret(decoded.substr(colon + 1), password);
    return u && p;
  }

  void Stream(const httplib::Request& req, httplib::Response& res) {
    int hz = kWebStreamDefaultHz;
    if (req.has_param("rate_hz")) {
      const std::string t = req.get_param_value("rate_hz");
      char* end = nullptr;
      const long v = std::strtol(t.c_str(), &end, 10);
      if (t.empty() || *end != 0 || v < 1 || v > kWebStreamMaxHz) {
        SendError(res, 400, "rate_hz must be 1 … " + std::to_string(kWebStreamMaxHz));
        return;
      }
      hz = static_cast<int>(v);
    }
    if (streams.fetch_add(1) >= kWebMaxStreams) {
      streams.fetch_sub(1);
      SendError(res, 503,
                "too many streams open (" + std::to_string(kWebMaxStreams) + "); poll instead");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    const auto period = std::chrono::microseconds(1000000 / hz);
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, period, next = std::chrono::steady_clock::now()](std::size_t,
                                                                httplib::DataSink& sink) mutable {
          if (stopping.load()) return false;
          std::this_thread::sleep_until(next);
          next += period;
          const auto now = std::chrono::steady_clock::now();
          if (next < now) next = now;  // fell behind (a slow client): no burst to catch up
          std::vector<std::uint16_t> in;
          std::string event;
          if (ReadMap(&in, nullptr)) {
            event = "event: live\ndata: " + LiveFromRegisters(in.data()).dump() + "\n\n";
          } else {
            event = "event: error\ndata: {\"error\":\"no sample could be read\"}\n\n";
          }
          return sink.write(event.data(), event.size());
        },
        [this](bool) { streams.fetch_sub(1, std::memory_order_relaxed); });
  }

  void Asset(const httplib::Request& req, httplib::Response& res) {
    const std::string path = req.path == "/" ? "/index.html" : req.path;
    for (const WebAsset& a : kWebAssets) {
      if (path == a.path) {
        res.set_content(reinterpret_cast<const char*>(a.data), a.size,
                        std::string(a.content_type) + "; charset=utf-8");
        res.set_header("Cache-Control", "no-cache");
        return;
      }
    }
    SendError(res, 404, "no such page");
  }

  void Routes() {
    httplib::Server& s = *server;
    s.set_payload_max_length(kWebMaxBodyBytes);
    s.set_keep_alive_max_count(1);
    s.set_read_timeout(5, 0);
    s.set_write_timeout(5, 0);
    s.new_task_queue = [] { return new httplib::ThreadPool(kWebThreads); };
    s.set_default_headers(
        {{"X-Content-Type-Options", "nosniff"},
         {"Content-Security-Policy", "default-src 'self'; style-src 'self' 'unsafe-inline'"},
         {"X-Frame-Options", "DENY"}});
    s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      requests.fetch_add(1, std::memory_order_relaxed);
      if (Authorized(req)) return httplib::Server::HandlerResponse::Unhandled;
      res.set_header("WWW-Authenticate", "Basic realm=\"ftd\", charset=\"UTF-8\"");
      SendError(res, 401, "user name or password wrong (--http-credentials)");
      return httplib::Server::HandlerResponse::Handled;
    });
    s.set_post_routing_handler([this](const httplib::Request&, httplib::Response& res) {
      if (res.status >= 400) errors.fetch_add(1, std::memory_order_relaxed);
    });
    s.set_error_handler([](const httplib::Request&, httplib::Response& res) {
      if (res.body.empty()) {
        const std::string m = res.status == 413 ? "request body larger than " +
                                                      std::to_string(kWebMaxBodyBytes) + " bytes"
                              : res.status == 404 ? "no such path"
                                                  : "bad request";
        SendError(res, res.status, m);
      }
    });
    for (const char* p :
         {"/", "/index.html", "/app.js", "/style.css", "/uPlot.iife.min.js", "/uPlot.min.css"}) {
      s.Get(p, [this](const httplib::Request& q, httplib::Response& r) { Asset(q, r); });
    }
    s.Get("/api/v1", [](const httplib::Request&, httplib::Response& r) {
      SendJson(
          r, 200,
          {{"api_version", kWebApiVersion},
           {"paths",
            {"GET /api/v1/info", "GET /api/v1/state", "GET /api/v1/wrench", "GET /api/v1/runtime",
             "GET /api/v1/stream", "POST /api/v1/command", "POST /api/v1/settings"}}});
    });
    s.Get("/api/v1/info",
          [this](const httplib::Request&, httplib::Response& r) { SendJson(r, 200, Info()); });
    s.Get("/api/v1/state", [this](const httplib::Request&, httplib::Response& r) {
      std::vector<std::uint16_t> in, hold;
      if (!ReadMap(&in, &hold)) return SendError(r, 503, "no sample could be read");
      nlohmann::json j = StateFromRegisters(in.data(), hold.data(), info);
      j["runtime"] = RuntimeJson();
      SendJson(r, 200, j);
    });
    s.Get("/api/v1/wrench", [this](const httplib::Request&, httplib::Response& r) {
      std::vector<std::uint16_t> in;
      if (!ReadMap(&in, nullptr)) return SendError(r, 503, "no sample could be read");
      SendJson(r, 200, LiveFromRegisters(in.data()));
    });
    s.Get("/api/v1/runtime", [this](const httplib::Request&, httplib::Response& r) {
      SendJson(r, 200, RuntimeJson());
    });
    s.Get("/api/v1/stream",
          [this](const httplib::Request& q, httplib::Response& r) { Stream(q, r); });
    s.Post("/api/v1/command",
           [this](const httplib::Request& q, httplib::Response& r) { Command(q, r); });
    s.Post("/api/v1/settings",
           [this](const httplib::Request& q, httplib::Response& r) { Settings(q, r); });
    // Every other method on a known path: 405 with Allow; an unknown path: 404.
    const auto other = [](const httplib::Request& q, httplib::Response& r) {
      for (const Route& rt : kRoutes) {
        if (q.path == rt.path) {
          r.set_header("Allow", rt.method);
          return SendError(r, 405,
                           q.method + " not allowed on " + q.path + " (" + rt.method + " only)");
        }
      }
      SendError(r, 404, "no such path");
    };
    s.Get(".*", other);
    s.Post(".*", other);
    s.Put(".*", other);
    s.Patch(".*", other);
    s.Delete(".*", other);
    s.Options(".*", other);
  }

  nlohmann::json RuntimeJson() const {
    nlohmann::json j = runtime ? runtime() : nlohmann::json::object();
    j["http"] = {{"requests", requests.load()},
                 {"errors", errors.load()},
                 {"writes", writes.load()},
                 {"streams_open", streams.load()}};
    return j;
  }
};

HttpServer::HttpServer(const FtdOptions& options, fw::RegisterMap* map, WebStaticInfo info,
                       std::function<nlohmann::json()> runtime)
    : impl_(std::make_unique<Impl>()) {
  impl_->opt = options;
  impl_->map = map;
  impl_->info = std::move(info);
  impl_->runtime = std::move(runtime);
}

HttpServer::~HttpServer() = default;

void HttpServer::Open() {
  Impl& m = *impl_;
  ParseHostPort(m.opt.http, &host_, &port_);
  if (!m.opt.http_credentials.empty()) {
    std::tie(m.user, m.password) =
        ReadCredentialsFile("--http-credentials", m.opt.http_credentials);
  }
  if (m.opt.http_cert.empty() != m.opt.http_key.empty()) {
    throw FtdError("--http-cert and --http-key go together");
  }
  if (!m.opt.http_cert.empty()) {
#ifdef CPPHTTPLIB_OPENSSL_SUPPORT
    auto ssl =
        std::make_unique<httplib::SSLServer>(m.opt.http_cert.c_str(), m.opt.http_key.c_str());
    if (!ssl->is_valid()) {
      throw FtdError("--http-cert " + m.opt.http_cert + " / --http-key " + m.opt.http_key +
                     ": not a usable PEM certificate and key");
    }
    m.server = std::move(ssl);
    tls_ = true;
#else
    throw FtdError("--http-cert: this ftd was built without HTTPS (FTSTACK_HTTPS=OFF)");
#endif
  } else {
    m.server = std::make_unique<httplib::Server>();
  }
  m.Routes();
  const int bound = port_ == 0 ? m.server->bind_to_any_port(host_)
                               : (m.server->bind_to_port(host_, port_) ? port_ : -1);
  if (bound <= 0) throw FtdError("web server on " + m.opt.http + ": cannot bind");
  port_ = static_cast<std::uint16_t>(bound);
}

void HttpServer::Run(const std::atomic<bool>& stop) {
  Impl& m = *impl_;
  std::thread watcher([&] {
    while (!stop.load(std::memory_order_relaxed)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    m.stopping = true;
    m.server->stop();
  });
  m.server->listen_after_bind();
  watcher.join();
}

WebStats HttpServer::stats() const {
  return {impl_->requests.load(), impl_->errors.load(), impl_->writes.load(),
          impl_->streams.load()};
}

bool WebServerBuilt() { return true; }
bool WebHttpsBuilt() {
#ifdef CPPHTTPLIB_OPENSSL_SUPPORT
  return true;
#else
  return false;
#endif
}

}  // namespace ftstack::daemon
