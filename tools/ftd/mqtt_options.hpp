// ftd's Sparkplug B / MQTT command-line options.
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/daemon.hpp"
#include "daemon/options.hpp"

namespace ftstack::tools {

/// Adds --mqtt and the options that go with it (broker TLS files, credentials file, Sparkplug
/// names, publish rate, keep-alive, write protection).
void AddMqttOptions(CLI::App& app, daemon::FtdOptions& opt);

/// One closing line on stderr with the publisher's counters (nothing without --mqtt).
void PrintMqttSummary(const daemon::Ftd& ftd);

}  // namespace ftstack::tools
