// ftd's OPC UA command-line options (--opcua and the options that go with it).
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/options.hpp"

namespace ftstack::tools {

/// Adds --opcua, --opcua-credentials, --opcua-cert, --opcua-key, --opcua-trust and
/// --opcua-write-protect (docs/opcua.md).
void AddOpcuaOptions(CLI::App& app, daemon::FtdOptions& opt);

}  // namespace ftstack::tools
