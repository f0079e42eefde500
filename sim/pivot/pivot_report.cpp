// The logic behind `ftsim pivot`: strict number parsing, solving, and text/JSON presentation.
#include "sim/pivot/pivot_report.hpp"

#include "sim/pivot/shape_registration.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <ostream>
#include <stdexcept>
#include <utility>

namespace ftstack::sim::pivot {

double ParseFiniteNumber(const std::string& text, const std::string& option) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  const bool consumed = end != begin && *end == '\0';
  if (text.empty() || !consumed || errno == ERANGE || !std::isfinite(v)) {
    throw std::invalid_argument(option + ": '" + text + "' is not a finite number");
  }
  return v;
}

PivotMethod ParsePivotMethod(const std::string& text) {
  if (text == "exact") return PivotMethod::kExact;
  if (text == "wittrick") return PivotMethod::kWittrick;
  throw std::invalid_argument("--method: '" + text + "' is not one of exact, wittrick");
}

nlohmann::json PivotResultToJson(const PivotGeometry& g, const PivotLoad& load,
                                 const PivotResult& r) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j;
  const std::pair<const char*, double> numbers[] = {
      {"C_Nm", r.c_nm},
      {"dX_m", r.dx_m},
      {"dY_m", r.dy_m},
      {"f1", r.f[0]},
      {"f2", r.f[1]},
      {"mB1", r.mb[0]},
      {"mB2", r.mb[1]},
      {"dC_dtheta_Nm_per_rad", r.dc_dtheta_nm_per_rad},
      {"N1_N", r.axial_n[0]},
      {"N2_N", r.axial_n[1]},
      {"MB1_Nm", r.moment_b_nm[0]},
      {"MB2_Nm", r.moment_b_nm[1]},
      {"max_stress_Pa", r.max_stress_pa},
      {"max_compression_N", r.max_compression_n}};
  for (const auto& [key, value] : numbers) j[key] = num(value);
  j["iterations"] = r.iterations;
  j["valid"] = r.valid;
  j["reason"] = r.reason;
  j["converged"] = r.converged;
  j["method"] = ToString(r.method);
  j["euler_load_N"] = g.EulerLoad();
  j["yield_Pa"] = g.yield_pa;
  j["EI_Nm2"] = g.BendingStiffness();
  j["inputs"] = {{"E_Pa", g.e_pa},
                 {"L_m", g.length_m},
                 {"b_m", g.width_m},
                 {"t_m", g.thickness_m},
                 {"alpha_deg", g.alpha_rad * 180.0 / std::numbers::pi},
                 {"lambda", g.crossing_fraction},
                 {"theta_deg", load.theta_rad * 180.0 / std::numbers::pi},
                 {"V_N", load.v_n},
                 {"H_N", load.h_n}};
  return j;
}

int RunPivotCommand(const PivotCommandArgs& args, std::ostream& out, std::ostream& err) {
  PivotGeometry g;
  PivotLoad load;
  PivotMethod method = kDefaultPivotMethod;
  std::vector<Eigen::Vector2d> measured;
  int strip = 1;
  try {
    constexpr double kDeg = std::numbers::pi / 180.0;
    g.e_pa = ParseFiniteNumber(args.e_pa, "--E");
    g.length_m = ParseFiniteNumber(args.length_m, "--L");
    g.width_m = ParseFiniteNumber(args.width_m, "--b");
    g.thickness_m = ParseFiniteNumber(args.thickness_m, "--t");
    g.alpha_rad = ParseFiniteNumber(args.alpha_deg, "--alpha-deg") * kDeg;
    g.yield_pa = ParseFiniteNumber(args.yield_pa, "--yield-pa");
    g.crossing_fraction = ParseFiniteNumber(args.lambda, "--lambda");
    load.theta_rad = ParseFiniteNumber(args.theta_deg, "--theta-deg") * kDeg;
    load.v_n = ParseFiniteNumber(args.v_n, "--V");
    load.h_n = ParseFiniteNumber(args.h_n, "--H");
    method = ParsePivotMethod(args.method);
    ValidateInputs(g, load);
    strip = args.strip == "1" ? 1 : args.strip == "2" ? 2 : 0;
    if (strip == 0) throw std::invalid_argument("--strip: '" + args.strip + "' is not 1 or 2");
    if (!args.shape_csv.empty()) measured = ReadPointsCsv(args.shape_csv);
  } catch (const std::invalid_argument& e) {
    err << "ftsim pivot: " << e.what() << '\n';
    return 2;
  }
  PivotOptions options;
  options.want_shape = !measured.empty();
  const PivotResult r = SolvePivot(g, load, method, options);
  nlohmann::json shape;  // null unless a shape was registered
  if (!measured.empty() && r.converged) {
    try {
      const ShapeRegistration reg = RegisterShape(r.shape_m[strip - 1], measured);
      shape = {{"strip", strip},
               {"points", measured.size()},
               {"scale_m_per_px", reg.measured_to_model.scale},
               {"rotation_deg", reg.measured_to_model.AngleRad() * 180.0 / std::numbers::pi},
               {"reflected", reg.measured_to_model.reflected},
               {"rms_residual_m", reg.rms_residual_m},
               {"max_residual_m", reg.max_residual_m},
               {"rms_residual_px", reg.rms_residual_m / reg.measured_to_model.scale}};
    } catch (const std::invalid_argument& e) {
      err << "ftsim pivot: " << args.shape_csv << ":1:1: " << e.what() << '\n';
      return 2;
    }
  }
  if (args.json) {
    nlohmann::json j = PivotResultToJson(g, load, r);
    if (!measured.empty()) j["shape"] = shape;
    out << j.dump() << '\n';
    return 0;
  }
  out << "method            " << ToString(r.method) << '\n'
      << "C                 " << r.c_nm << " N*m\n"
      << "dX, dY            " << r.dx_m << ", " << r.dy_m << " m\n"
      << "f1, f2            " << r.f[0] << ", " << r.f[1] << "  (N*L^2/EI, tension > 0)\n"
      << "mB1, mB2          " << r.mb[0] << ", " << r.mb[1] << "  (M_B*L/EI)\n"
      << "dC/dtheta         " << r.dc_dtheta_nm_per_rad << " N*m/rad\n"
      << "max stress        " << r.max_stress_pa / 1e6 << " MPa (yield " << g.yield_pa / 1e6
      << ")\n"
      << "max compression   " << r.max_compression_n << " N (Euler " << g.EulerLoad() << ")\n"
      << "iterations        " << r.iterations << '\n'
      << "valid             " << (r.valid ? "yes" : "no") << '\n';
  if (!r.valid) out << "reason            " << r.reason << '\n';
  if (!shape.is_null()) {
    out << "shape (strip " << strip << ")     registered RMS residual "
        << shape["rms_residual_m"].get<double>() << " m (" << shape["rms_residual_px"].get<double>()
        << " px), scale " << shape["scale_m_per_px"].get<double>() << " m/px\n";
  }
  return 0;
}

}  // namespace ftstack::sim::pivot
