// The seam between ftd and where its samples come from: an ADC backend (hardware or simulated).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "calibration/file/cal_file.hpp"
#include "hal/adc.hpp"

namespace ftstack::daemon {

struct FtdOptions;

/// An ADC and whatever it reads from, owned together for the daemon's lifetime.
class AdcBackend {
 public:
  virtual ~AdcBackend() = default;
  [[nodiscard]] virtual hal::Adc& adc() = 0;
  [[nodiscard]] virtual std::uint8_t channel_count() const = 0;
  /// The PGA gain to configure (1 where the converter has none to choose).
  [[nodiscard]] virtual std::uint16_t gain() const { return 1; }
  /// The calibration to run with when no --cal is given, for the configured converter `adc`;
  /// nullopt: this backend needs a calibration file.
  [[nodiscard]] virtual std::optional<cal::CalFile> BuiltinCalibration(
      const hal::AdcInfo& adc) const {
    (void)adc;
    return std::nullopt;
  }
};

/// Makes the simulated backend (`--adc sim`). Host builds of ftd pass MakeSimulatedBackend
/// (daemon/sim/sim_backend.hpp); a board build passes nullptr and refuses `--adc sim`.
using SimulatorFactory = std::unique_ptr<AdcBackend> (*)(const FtdOptions& options);

}  // namespace ftstack::daemon
