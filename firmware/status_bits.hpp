// The sensor status bits published in Modbus input register 1 (docs/spec/modbus-map.md).
#pragma once

#include <cstdint>

namespace ftstack::fw {

/// Status bits, as in the Modbus register map (input register 1).
enum StatusBit : std::uint16_t {
  kStatusSaturated = 1u << 0,    ///< a bridge within 1 % of its rail; wrench holds last valid
  kStatusOverload = 1u << 1,     ///< combined load above 105 % of rated
  kStatusBridgeFault = 1u << 2,  ///< open or shorted gauge / bridge
  kStatusAdcFault = 1u << 3,     ///< no data-ready in time, stuck value, or read error
  kStatusCalInvalid = 1u << 4,   ///< no valid calibration; wrench registers 0 / NaN
  kStatusTareActive = 1u << 5,   ///< a tare is applied
  kStatusTempRange = 1u << 6,    ///< temperature outside the compensated range
  kStatusSimulated = 1u << 7,    ///< simulated ADC backend
  kStatusStale = 1u << 8,        ///< no new sample within 2 sample periods
  kStatusLate = 1u << 9,         ///< a sample was read > 1.5 periods after the previous one
  /// The calibration flags an axis invalid (its rig never excited it): that axis's wrench
  /// registers read NaN / 0 (in the tool frame: every axis the transform mixes it into).
  kStatusAxisInvalid = 1u << 10,
  kStatusPayloadComp = 1u << 12,  ///< the payload's weight and moment (and bias) are subtracted
};

}  // namespace ftstack::fw
