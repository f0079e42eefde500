#include "sim/design/one_design.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include "measurement/wrench.hpp"

namespace ftstack::sim::design {
namespace {

double ParseNumber(const std::string& key, const std::string& text) {
  std::size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v)) {
    throw std::invalid_argument("design spec: " + key + "=" + text + " is not a finite number");
  }
  return v;
}

/// Applies "key=value,..." to the named fields; an unknown key is an error listing the known ones.
void ApplyPairs(const std::string& family, const std::string& pairs,
                const std::map<std::string, std::function<void(double)>>& fields) {
  std::stringstream ss(pairs);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::invalid_argument("design spec: '" + item + "' is not key=value");
    }
    const std::string key = item.substr(0, eq);
    const auto it = fields.find(key);
    if (it == fields.end()) {
      std::string known;
      for (const auto& [k, f] : fields) known += (known.empty() ? "" : ", ") + k;
      throw std::invalid_argument("design spec: " + family + " has no parameter '" + key +
                                  "' (known: " + known + ")");
    }
    it->second(ParseNumber(key, item.substr(eq + 1)));
  }
}

}  // namespace

DesignModel ModelFromSpec(const std::string& spec, const Readout& r) {
  const auto colon = spec.find(':');
  const std::string family = spec.substr(0, colon);
  const std::string pairs = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (family == "hub-spoke") {
    HubSpokeParams p;
    double beams = p.beams;
    ApplyPairs(family, pairs,
               {{"beams", [&](double v) { beams = v; }},
                {"hub_radius_m", [&](double v) { p.hub_radius_m = v; }},
                {"rim_radius_m", [&](double v) { p.rim_radius_m = v; }},
                {"beam_width_m", [&](double v) { p.beam_width_m = v; }},
                {"beam_height_m", [&](double v) { p.beam_height_m = v; }},
                {"gauge_frac", [&](double v) { p.gauge_frac = v; }},
                {"elastic_roots", [&](double v) { p.elastic_roots = v != 0; }}});
    if (beams != 3 && beams != 4) throw std::invalid_argument("design spec: beams must be 3 or 4");
    p.beams = static_cast<int>(beams);
    return HubSpoke(p, r);
  }
  if (family == "guided") {
    GuidedParams p;
    ApplyPairs(family, pairs,
               {{"leaf_length_m", [&](double v) { p.leaf_length_m = v; }},
                {"leaf_width_m", [&](double v) { p.leaf_width_m = v; }},
                {"leaf_thickness_m", [&](double v) { p.leaf_thickness_m = v; }},
                {"leaf_thickness_z_m", [&](double v) { p.leaf_thickness_z_m = v; }},
                {"separation_m", [&](double v) { p.separation_m = v; }},
                {"inner_radius_m", [&](double v) { p.inner_radius_m = v; }},
                {"gap_m", [&](double v) { p.gap_m = v; }},
                {"gauge_frac", [&](double v) { p.gauge_frac = v; }}});
    return Guided(p, r);
  }
  throw std::invalid_argument("design spec: unknown family '" + family +
                              "' (hub-spoke or guided), in '" + spec + "'");
}

std::string SpecOf(const DesignModel& m) {
  std::string s = m.family + ":";
  bool first = true;
  for (const auto& [k, v] : m.parameters) {
    if (k == "envelope_radius_m") continue;  // derived, not a parameter
    s += fmt::format("{}{}={:.6g}", first ? "" : ",", k, v);
    first = false;
  }
  return s;
}

void PrintDesignDetail(std::ostream& out, const Candidate& c, const DesignOptions& o) {
  const DesignFigures& f = c.figures;
  PrintDesign(out, c, o);
  out << "  spec: " << SpecOf(c.model) << "\n";
  out << "  beam theory: "
      << (c.model.beam_validity.empty()
              ? std::string("every member is a slender beam (L >= 2 h; leaf width L >= b/2)")
              : "OUTSIDE the slender-beam range (" + c.model.beam_validity +
                    "): figures need a solid FE check")
      << "\n  stiffness at the origin (rows/cols Fx Fy Fz Mx My Mz; N/m, N/rad, N·m/rad):\n";
  for (int i = 0; i < 6; ++i) {
    out << "   ";
    for (int j = 0; j < 6; ++j) out << fmt::format(" {:11.4g}", f.stiffness(i, j));
    out << "\n";
  }
  out << "  gauge strain per unit wrench (µε per N or N·m):\n    #  gauge" << std::string(34, ' ');
  for (int k = 0; k < 6; ++k) out << fmt::format(" {:>9}", kWrenchAxisNames[k]);
  out << "\n";
  for (Eigen::Index g = 0; g < c.model.gauge_strain.rows(); ++g) {
    const std::string name = static_cast<std::size_t>(g) < c.model.gauges.size()
                                 ? c.model.gauges[static_cast<std::size_t>(g)].name
                                 : "";
    out << fmt::format("  {:3d}  {:<38}", g, name);
    for (int k = 0; k < 6; ++k) out << fmt::format(" {:9.4g}", 1e6 * c.model.gauge_strain(g, k));
    out << "\n";
  }
  out << "  bridge outputs (mV/V per N or N·m):\n";
  for (Eigen::Index b = 0; b < c.model.sensitivity_mvv.rows(); ++b) {
    out << fmt::format("    bridge {}", b);
    for (int k = 0; k < 6; ++k) out << fmt::format(" {:10.4g}", c.model.sensitivity_mvv(b, k));
    out << "\n";
  }
  out << "  capacities alone, binding limit:";
  for (int k = 0; k < 6; ++k) {
    out << fmt::format(" {} {:.4g} {} ({})", kWrenchAxisNames[k], f.capacity(k),
                       kWrenchAxisUnits[k], ToString(f.binding[static_cast<std::size_t>(k)]));
  }
  out << fmt::format("\n  modes with a {:.2f} kg tool (Hz):", o.tool_mass_kg);
  for (int k = 0; k < 6; ++k) out << fmt::format(" {:.4g}", f.natural_hz(k));
  out << "\n";
}

nlohmann::json DesignJson(const Candidate& c, const DesignOptions& o) {
  const DesignFigures& f = c.figures;
  auto vec = [](const Vec6& v) { return std::vector<double>(v.data(), v.data() + 6); };
  nlohmann::json j;
  j["schema"] = "ftstack-design/1";
  j["id"] = c.id;
  j["family"] = c.model.family;
  j["spec"] = SpecOf(c.model);
  j["material"] = {{"name", c.model.material.name},
                   {"e_pa", c.model.material.e_pa},
                   {"poisson", c.model.material.poisson},
                   {"yield_pa", c.model.material.yield_pa}};
  j["parameters"] = c.model.parameters;
  j["slender_beams"] = c.model.beam_validity.empty();
  j["beam_validity"] = c.model.beam_validity;
  j["wrench_order"] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  nlohmann::json k = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) {
    k.push_back(std::vector<double>{f.stiffness(i, 0), f.stiffness(i, 1), f.stiffness(i, 2),
                                    f.stiffness(i, 3), f.stiffness(i, 4), f.stiffness(i, 5)});
  }
  j["stiffness_si"] = k;
  nlohmann::json gauges = nlohmann::json::array();
  for (Eigen::Index g = 0; g < c.model.gauge_strain.rows(); ++g) {
    nlohmann::json row;
    const Row6 s = c.model.gauge_strain.row(g);
    row["strain_per_unit_wrench"] = std::vector<double>(s.data(), s.data() + 6);
    if (static_cast<std::size_t>(g) < c.model.gauges.size()) {
      const GaugeGrid& gr = c.model.gauges[static_cast<std::size_t>(g)];
      row["name"] = gr.name;
      row["point_m"] = {gr.point_m.x(), gr.point_m.y(), gr.point_m.z()};
      row["direction"] = {gr.direction.x(), gr.direction.y(), gr.direction.z()};
      row["normal"] = {gr.normal.x(), gr.normal.y(), gr.normal.z()};
    }
    gauges.push_back(row);
  }
  j["gauges"] = gauges;
  nlohmann::json bridges = nlohmann::json::array();
  for (Eigen::Index b = 0; b < c.model.sensitivity_mvv.rows(); ++b) {
    const Row6 s = c.model.sensitivity_mvv.row(b);
    bridges.push_back(std::vector<double>(s.data(), s.data() + 6));
  }
  j["bridge_mvv_per_unit_wrench"] = bridges;
  std::vector<std::string> binding;
  for (Limit l : f.binding) binding.push_back(ToString(l));
  j["capacity"] = {{"per_axis", vec(f.capacity)},
                   {"binding", binding},
                   {"safety_factor", o.safety_factor},
                   {"combined_scale", f.combined_scale}};
  j["resolution"] = {{"per_axis", vec(f.resolution)}, {"bandwidth_hz", f.bandwidth_hz}};
  j["natural_hz"] = vec(f.natural_hz);
  j["tool"] = {
      {"mass_kg", o.tool_mass_kg}, {"com_z_m", o.tool_com_z_m}, {"gyration_m", o.tool_gyration_m}};
  j["force_range_n"] = f.force_range_n;
  j["force_resolution_n"] = f.force_resolution_n;
  j["tilt_capacity_nm"] = f.tilt_capacity_nm;
  j["overload_margin"] = f.overload_margin;
  return j;
}

}  // namespace ftstack::sim::design
