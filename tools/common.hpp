// Small helpers shared by the command-line tools: parsing wrench lists, one-line error exits.
#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "firmware/status_bits.hpp"

namespace ftstack::tools {

/// Parses "FX,FY,FZ,MX,MY,MZ" (N, N·m); throws std::invalid_argument naming the bad field.
inline std::array<double, 6> ParseWrench(const std::string& text) {
  std::array<double, 6> w{};
  std::stringstream ss(text);
  std::string field;
  std::size_t i = 0;
  while (std::getline(ss, field, ',')) {
    if (i >= 6) throw std::invalid_argument("wrench '" + text + "' has more than 6 values");
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != field.size() || !std::isfinite(v)) {
      throw std::invalid_argument("wrench value " + std::to_string(i + 1) + " ('" + field +
                                  "') is not a finite number");
    }
    w[i++] = v;
  }
  if (i != 6) throw std::invalid_argument("wrench '" + text + "' needs 6 values FX,FY,FZ,MX,MY,MZ");
  return w;
}

/// Status bits that make a row's wrench not a valid reading (saturation, overload, bridge or ADC
/// fault, no calibration, temperature out of range, stale); the others (tare, simulated, late)
/// are information.
inline constexpr std::uint16_t kFlaggingBits =
    fw::kStatusSaturated | fw::kStatusOverload | fw::kStatusBridgeFault | fw::kStatusAdcFault |
    fw::kStatusCalInvalid | fw::kStatusTempRange | fw::kStatusStale;

/// Prints, for every status bit some row carries, how many rows carry it; returns the number of
/// rows with a flagging bit (kFlaggingBits).
inline std::size_t ReportStatusBits(const std::vector<double>& status, std::FILE* out) {
  static const char* const kNames[10] = {"saturated",
                                         "overload",
                                         "bridge fault",
                                         "ADC fault",
                                         "cal invalid",
                                         "tare active",
                                         "temperature out of range",
                                         "simulated",
                                         "stale",
                                         "late"};
  std::size_t count[16] = {};
  std::size_t flagged = 0;
  for (const double s : status) {
    const auto bits = static_cast<std::uint16_t>(s);
    for (int b = 0; b < 16; ++b) count[b] += (bits >> b) & 1u;
    flagged += (bits & kFlaggingBits) != 0 ? 1 : 0;
  }
  for (int b = 0; b < 16; ++b) {
    if (count[b] == 0) continue;
    std::fprintf(out, "ftcal: status bit %d (%s): %zu of %zu rows\n", b, b < 10 ? kNames[b] : "?",
                 count[b], status.size());
  }
  return flagged;
}

}  // namespace ftstack::tools
