#include "daemon/opcua_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "daemon/opcua_impl.hpp"

namespace ftstack::daemon {
namespace {

/// open62541's messages, warnings and worse, on stderr (its default logger writes to stdout,
/// where ftd prints its readings).
void LogToStderr(void* quiet, UA_LogLevel level, UA_LogCategory, const char* msg, va_list args) {
  if (level < UA_LOGLEVEL_WARNING || *static_cast<bool*>(quiet)) return;
  std::fprintf(stderr, "ftd: opcua: ");
  std::vfprintf(stderr, msg, args);
  std::fputc('\n', stderr);
}
/// Quiet while the access control is set up: open62541 warns on every set-up that a logged-in
/// user has all rights (true: ftd has no per-node rights, docs/opcua.md).
bool g_log_quiet = false;
UA_Logger g_logger{LogToStderr, &g_log_quiet, nullptr};

UA_StatusCode RejectUserCertificate(const UA_CertificateVerification*, const UA_ByteString*) {
  return UA_STATUSCODE_BADCERTIFICATEUNTRUSTED;
}

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

/// A free TCP port on `host` (the kernel's choice for port 0); open62541 binds it right after.
std::uint16_t FreePort(const std::string& host) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw FtdError("--opcua: no socket for choosing a free port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = 0;
  if (::inet_pton(AF_INET, host == "localhost" ? "127.0.0.1" : host.c_str(), &a.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    throw FtdError("--opcua " + host + ":0: cannot bind an IPv4 address there");
  }
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

/// The whole file as a byte string (certificate, key: DER or PEM); throws FtdError naming it.
UA_ByteString ReadBytes(const std::string& option, const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw FtdError(option + " '" + path + "': cannot be read");
  const std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (s.empty()) throw FtdError(option + " '" + path + "': empty file");
  UA_ByteString b;
  if (UA_ByteString_allocBuffer(&b, s.size()) != UA_STATUSCODE_GOOD) {
    throw FtdError(option + ": out of memory");
  }
  std::copy(s.begin(), s.end(), b.data);
  return b;
}

/// Frees the byte strings on every path out of Open.
struct ByteStrings {
  std::vector<UA_ByteString> v;
  ~ByteStrings() {
    for (UA_ByteString& b : v) UA_ByteString_clear(&b);
  }
};

void Check(UA_StatusCode rc, const std::string& what) {
  if (rc != UA_STATUSCODE_GOOD) {
    throw FtdError("--opcua: " + what + ": " + UA_StatusCode_name(rc));
  }
}

}  // namespace

OpcuaServer::OpcuaServer(const FtdOptions& options, fw::RegisterMap* map, OpcuaDeviceInfo info)
    : impl_(std::make_unique<Impl>(options, map, std::move(info))) {}

OpcuaServer::~OpcuaServer() = default;

OpcuaStats OpcuaServer::stats() const {
  return {impl_->method_calls.load(), impl_->method_refused.load()};
}

void OpcuaServer::Open() {
  const FtdOptions& opt = impl_->opt;
  ParseHostPort(opt.opcua, &host_, &port_);
  secure_ = !opt.opcua_cert.empty();
  const bool loopback = IsLoopback(host_);
  if (!secure_ && !loopback) {
    throw FtdError("--opcua " + opt.opcua +
                   ": security None only on a loopback address; give --opcua-cert and "
                   "--opcua-key for Basic256Sha256");
  }
  if (port_ == 0) port_ = FreePort(host_);

  ByteStrings files;
  UA_ServerConfig c;
  std::memset(&c, 0, sizeof c);
  c.logging = &g_logger;
  g_log_quiet = true;
  const UA_StatusCode basics = UA_ServerConfig_setBasics_withPort(&c, port_);
  g_log_quiet = false;
  Check(basics, "configuration");
  // Listen on the asked address only.
  UA_Array_delete(c.serverUrls, c.serverUrlsSize, &UA_TYPES[UA_TYPES_STRING]);
  const std::string url = "opc.tcp://" + host_ + ":" + std::to_string(port_);
  c.serverUrls = UA_String_new();
  *c.serverUrls = UA_STRING_ALLOC(url.c_str());
  c.serverUrlsSize = 1;
  c.maxSessions = kOpcuaMaxSessions;
  // A value may be absent (Bad status, no value: never a guessed one), also while nodes are added.
  c.allowEmptyVariables = UA_RULEHANDLING_ACCEPT;
  c.samplingIntervalLimits.min = kOpcuaMinIntervalMs;
  c.publishingIntervalLimits.min = kOpcuaMinIntervalMs;
  UA_String_clear(&c.applicationDescription.applicationUri);
  c.applicationDescription.applicationUri = UA_STRING_ALLOC("urn:ftstack:ftd");
  UA_LocalizedText_clear(&c.applicationDescription.applicationName);
  c.applicationDescription.applicationName = UA_LOCALIZEDTEXT_ALLOC("en", "ftd");

  // No certificate user tokens: a user is anonymous or has the credentials file's password (the
  // default session PKI accepts any certificate as a user identity, which would bypass the
  // password). Without a verifier the access control offers no certificate token; the rejecting
  // one set after it refuses such a token should a client send one anyway.
  c.sessionPKI.verifyCertificate = nullptr;
  try {
    if (secure_) {
      files.v.push_back(ReadBytes("--opcua-cert", opt.opcua_cert));
      files.v.push_back(ReadBytes("--opcua-key", opt.opcua_key));
      std::vector<UA_ByteString> trust;
      for (const std::string& t : opt.opcua_trust) {
        files.v.push_back(ReadBytes("--opcua-trust", t));
        trust.push_back(files.v.back());
      }
      // Only the listed client certificates open a secure channel (none listed: none does).
      if (c.secureChannelPKI.clear != nullptr) c.secureChannelPKI.clear(&c.secureChannelPKI);
      Check(UA_CertificateVerification_Trustlist(&c.secureChannelPKI, trust.data(), trust.size(),
                                                 nullptr, 0, nullptr, 0),
            "trust list");
      Check(UA_ServerConfig_addSecurityPolicyBasic256Sha256(&c, &files.v[0], &files.v[1]),
            "certificate and key (DER or PEM, RSA 2048–4096)");
      Check(UA_ServerConfig_addEndpoint(
                &c,
                UA_STRING(
                    const_cast<char*>("http://opcfoundation.org/UA/SecurityPolicy#Basic256Sha256")),
                UA_MESSAGESECURITYMODE_SIGNANDENCRYPT),
            "endpoint Basic256Sha256");
    }
    if (loopback) {
      Check(UA_ServerConfig_addSecurityPolicyNone(&c, secure_ ? &files.v[0] : nullptr),
            "security None");
      Check(UA_ServerConfig_addEndpoint(
                &c, UA_STRING(const_cast<char*>("http://opcfoundation.org/UA/SecurityPolicy#None")),
                UA_MESSAGESECURITYMODE_NONE),
            "endpoint None");
    }
    if (!opt.opcua_credentials.empty()) {
      const auto [user, password] =
          ReadCredentialsFile("--opcua-credentials", opt.opcua_credentials);
      UA_UsernamePasswordLogin login;
      login.username = UA_STRING(const_cast<char*>(user.c_str()));
      login.password = UA_STRING(const_cast<char*>(password.c_str()));
      // A password crosses a None channel in clear: only on loopback, else encrypted with the
      // server's key (the user token's own policy).
      c.allowNonePolicyPassword = loopback;
      g_log_quiet = true;
      const UA_StatusCode ac = UA_AccessControl_default(&c, false, nullptr, 1, &login);
      g_log_quiet = false;
      Check(ac, "access control");
    } else {
      g_log_quiet = true;
      const UA_StatusCode ac = UA_AccessControl_default(&c, true, nullptr, 0, nullptr);
      g_log_quiet = false;
      Check(ac, "access control");
    }
    c.sessionPKI.verifyCertificate = RejectUserCertificate;
  } catch (...) {
    UA_ServerConfig_clean(&c);
    throw;
  }
  impl_->server = UA_Server_newWithConfig(&c);
  if (impl_->server == nullptr) throw FtdError("--opcua: the server could not be created");
  impl_->ns = UA_Server_addNamespace(impl_->server, kOpcuaNamespace);
  impl_->di_ns = UA_Server_addNamespace(impl_->server, kOpcuaDiNamespace);
  impl_->BuildAddressSpace();
  if (!OpcuaSendBatch::Install(impl_->server)) throw FtdError("--opcua: no TCP connection manager");
  Check(UA_Server_run_startup(impl_->server), "cannot listen on " + url);
}

void OpcuaServer::Run(const std::atomic<bool>& stop) {
  // While a callback (a subscription's publish cycle) is due within one round, the thread works
  // in rounds on a fixed grid: everything due in a round, network input included, is handled in
  // one wake-up. Each subscription's timer has its own phase, and a wake-up costs more than the
  // work it does; without fast callbacks the thread sleeps until input or the next callback.
  using Clock = std::chrono::steady_clock;
  // What an iteration sends on a connection leaves in one send at its end.
  const auto round = std::chrono::milliseconds(static_cast<int>(kOpcuaMinIntervalMs));
  impl_->send_batch.Begin();
  while (!stop.load(std::memory_order_relaxed)) {
    impl_->iteration.fetch_add(1, std::memory_order_relaxed);
    const UA_UInt16 next_ms = UA_Server_run_iterate(impl_->server, false);
    impl_->send_batch.Flush();
    if (next_ms >= round.count()) {
      impl_->iteration.fetch_add(1, std::memory_order_relaxed);
      UA_Server_run_iterate(impl_->server, true);
      impl_->send_batch.Flush();
      continue;
    }
    const auto since = Clock::now().time_since_epoch();
    std::this_thread::sleep_until(Clock::time_point((since / round + 1) * round));
  }
  impl_->send_batch.End();
  UA_Server_run_shutdown(impl_->server);
}

UA_StatusCode OpcuaServer::Impl::Command(std::uint16_t addr, std::uint16_t value) {
  method_calls.fetch_add(1, std::memory_order_relaxed);
  if (opt.opcua_write_protect) {
    method_refused.fetch_add(1, std::memory_order_relaxed);
    return UA_STATUSCODE_BADUSERACCESSDENIED;
  }
  const fw::ModbusException e = map->WriteHolding(addr, &value, 1, fw::TareSource::kOpcua);
  if (e == fw::ModbusException::kNone) return UA_STATUSCODE_GOOD;
  method_refused.fetch_add(1, std::memory_order_relaxed);
  return e == fw::ModbusException::kIllegalDataValue ? UA_STATUSCODE_BADINVALIDARGUMENT
                                                     : UA_STATUSCODE_BADINTERNALERROR;
}

UA_StatusCode OpcuaServer::Impl::SelectSlot(std::uint16_t slot) {
  // The slot register is protected: unlock (holding 4) and write it, as a Modbus master does.
  if (opt.opcua_write_protect) return Command(fw::kHoldCalSlot, slot);
  const std::uint16_t key = fw::kUnlockKey;
  if (map->WriteHolding(fw::kHoldUnlock, &key, 1, fw::TareSource::kOpcua) !=
      fw::ModbusException::kNone) {
    return UA_STATUSCODE_BADINTERNALERROR;
  }
  return Command(fw::kHoldCalSlot, slot);
}

}  // namespace ftstack::daemon
