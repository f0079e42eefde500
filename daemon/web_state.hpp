// The web API's state object: the register map's input and holding tables decoded into JSON.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace ftstack::daemon {

/// One calibration slot as the page names it (from its file; the built-in one has no file).
struct WebCalLabel {
  bool present = false;
  std::string file;  ///< "" for the built-in calibration
  std::string serial;
  std::string date;
};

/// What does not change while ftd runs: rated range, calibration labels, configured rate.
struct WebStaticInfo {
  std::array<double, 6> rated{};  ///< N and N·m per axis (all 0: no rating, no overload rule)
  std::array<WebCalLabel, 2> slots{};
  unsigned rate_hz = 0;
  std::string adc;
};

/// Decodes the whole input table (`in`, kInputAddressSpan registers) and the holding registers
/// (`hold`, kHoldingRegisterSpan) into the API's state object (docs/web.md): the same numbers a
/// Modbus master reads, with the status bits, causes and states in words.
[[nodiscard]] nlohmann::json StateFromRegisters(const std::uint16_t* in, const std::uint16_t* hold,
                                                const WebStaticInfo& info);
/// The stream's event: the live part of StateFromRegisters (wrench, status, health).
[[nodiscard]] nlohmann::json LiveFromRegisters(const std::uint16_t* in);

}  // namespace ftstack::daemon
