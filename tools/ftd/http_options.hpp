// ftd's web page command-line options (--http and the options that go with it).
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/options.hpp"

namespace ftstack::tools {

/// Adds --http, --http-credentials, --http-cert, --http-key and --http-write-protect (docs/web.md).
void AddHttpOptions(CLI::App& app, daemon::FtdOptions& opt);

}  // namespace ftstack::tools
