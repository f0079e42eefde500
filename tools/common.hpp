// Small helpers shared by the command-line tools: parsing wrench lists, one-line error exits.
#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

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

}  // namespace ftstack::tools
