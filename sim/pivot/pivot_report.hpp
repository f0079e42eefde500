// The logic behind `ftsim pivot`: strict number parsing, solving, and text/JSON presentation.
#pragma once

#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/pivot/pivot.hpp"

namespace ftstack::sim::pivot {

/// The command's arguments as typed (strings, so every number is checked the same strict way).
struct PivotCommandArgs {
  std::string e_pa, length_m, width_m, thickness_m, alpha_deg, theta_deg, v_n, h_n;
  std::string yield_pa = "1e9";
  std::string lambda = "0.5";
  std::string method = "exact";
  bool json = false;
  /// Optional: measured edge points of one strip (pixels, any frame; see ReadPointsCsv) to register
  /// onto the model's deformed strip `strip` (1 or 2); adds a "shape" object to the output.
  std::string shape_csv;
  std::string strip = "1";
};

/// Parses a whole string as a finite double; throws std::invalid_argument naming `option`.
[[nodiscard]] double ParseFiniteNumber(const std::string& text, const std::string& option);

/// "exact" or "wittrick"; throws std::invalid_argument otherwise.
[[nodiscard]] PivotMethod ParsePivotMethod(const std::string& text);

/// One JSON object: C_Nm, dX_m, dY_m, f1, f2, mB1, mB2, iterations, valid, reason, plus method,
/// dC_dtheta_Nm_per_rad, N1_N, N2_N, MB1_Nm, MB2_Nm, max_stress_Pa, max_compression_N,
/// euler_load_N, yield_Pa, converged, and the inputs.
[[nodiscard]] nlohmann::json PivotResultToJson(const PivotGeometry& g, const PivotLoad& load,
                                               const PivotResult& r);

/// Runs the command: prints the result to `out` (JSON or text) and returns 0; on bad input
/// (numbers, method, strip, shape file) prints one line "ftsim pivot: <reason>" to `err` and
/// returns 2.
int RunPivotCommand(const PivotCommandArgs& args, std::ostream& out, std::ostream& err);

}  // namespace ftstack::sim::pivot
