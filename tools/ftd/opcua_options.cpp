#include "tools/ftd/opcua_options.hpp"

namespace ftstack::tools {

void AddOpcuaOptions(CLI::App& app, daemon::FtdOptions& opt) {
  auto* opcua = app.add_option("--opcua", opt.opcua,
                               "serve OPC UA on HOST:PORT (e.g. 127.0.0.1:4840; 0: any free port; "
                               "security None only on loopback)");
  app.add_option("--opcua-credentials", opt.opcua_credentials,
                 "file with the user name (line 1) and password (line 2): anonymous off")
      ->check(CLI::ExistingFile)
      ->needs(opcua);
  auto* cert = app.add_option("--opcua-cert", opt.opcua_cert,
                              "server certificate (DER or PEM): Basic256Sha256 Sign&Encrypt")
                   ->check(CLI::ExistingFile)
                   ->needs(opcua);
  auto* key = app.add_option("--opcua-key", opt.opcua_key, "the certificate's private key")
                  ->check(CLI::ExistingFile)
                  ->needs(opcua);
  cert->needs(key);
  key->needs(cert);
  app.add_option("--opcua-trust", opt.opcua_trust,
                 "client certificate trusted for Basic256Sha256 (repeat for more)")
      ->check(CLI::ExistingFile)
      ->needs(cert);
  app.add_flag("--opcua-write-protect", opt.opcua_write_protect,
               "OPC UA clients only read: every method call (Tare, SelectSlot, ...) is refused")
      ->needs(opcua);
}

}  // namespace ftstack::tools
