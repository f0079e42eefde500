#include "tools/ftd/http_options.hpp"

namespace ftstack::tools {

void AddHttpOptions(CLI::App& app, daemon::FtdOptions& opt) {
  auto* http = app.add_option(
      "--http", opt.http,
      "serve the web page and JSON API on HOST:PORT (e.g. 127.0.0.1:8080; 0: any free port)");
  app.add_option("--http-credentials", opt.http_credentials,
                 "file with the page's user name (line 1) and password (line 2): HTTP Basic auth")
      ->check(CLI::ExistingFile)
      ->needs(http);
  auto* cert = app.add_option("--http-cert", opt.http_cert, "PEM certificate: serve HTTPS")
                   ->check(CLI::ExistingFile)
                   ->needs(http);
  auto* key = app.add_option("--http-key", opt.http_key, "the certificate's PEM private key")
                  ->check(CLI::ExistingFile)
                  ->needs(http);
  cert->needs(key);
  key->needs(cert);
  app.add_flag("--http-write-protect", opt.http_write_protect,
               "the page and API only read: every write (tare, settings) is refused")
      ->needs(http);
}

}  // namespace ftstack::tools
