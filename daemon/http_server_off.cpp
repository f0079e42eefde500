// ftd built without cpp-httplib (FTSTACK_HTTP off or the package missing): --http is refused.
#include "daemon/http_server.hpp"

namespace ftstack::daemon {

struct HttpServer::Impl {};

HttpServer::HttpServer(const FtdOptions&, fw::RegisterMap*, WebStaticInfo,
                       std::function<nlohmann::json()>) {}
HttpServer::~HttpServer() = default;
void HttpServer::Open() {
  throw FtdError("--http: this ftd was built without the web server (libcpp-httplib-dev)");
}
void HttpServer::Run(const std::atomic<bool>&) {}
WebStats HttpServer::stats() const { return {}; }
bool WebServerBuilt() { return false; }
bool WebHttpsBuilt() { return false; }

}  // namespace ftstack::daemon
