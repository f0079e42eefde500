// ftd's command-line options of where samples come from: the ADC backend, a replayed recording
// and its bridge unit, the hardware converter's device.
#pragma once

#include <CLI/CLI.hpp>

#include "daemon/options.hpp"

namespace ftstack::tools {

/// Adds --adc, --replay with the unit options (--bridge-unit, --converter, --excitation-v: how
/// --adc replay reads the recording's bridges), --gpiochip and --spidev.
void AddSourceOptions(CLI::App& app, daemon::FtdOptions& opt);

}  // namespace ftstack::tools
