// ftd's simulated backend: the built-in sensor description → simulated sensor → simulated ADC.
#pragma once

#include <memory>

#include "daemon/backend.hpp"
#include "daemon/daemon.hpp"

namespace ftstack::daemon {

/// The built-in sensor (sim/sensors/default.json) under a constant wrench (--sim-wrench) or a
/// replayed recording (--replay), read by its own converter at the requested rate; with no --cal
/// it runs on the sensor's ideal calibration. Throws on a bad replay file.
[[nodiscard]] std::unique_ptr<AdcBackend> MakeSimulatedBackend(const FtdOptions& options);

}  // namespace ftstack::daemon
