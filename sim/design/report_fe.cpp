#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "measurement/wrench.hpp"
#include "sim/design/report.hpp"

namespace ftstack::sim::design {
namespace {

struct RatioRow {
  std::string label;
  double model = 0, fe = 0, mesh_change = 0;
};

std::vector<RatioRow> Rows(const FeCheck& c) {
  std::vector<RatioRow> rows;
  const FeSolution& fe = c.meshes.back();
  const FeSolution& first = c.meshes.front();
  for (int k = 0; k < 6; ++k) {
    rows.push_back({fmt::format("K {}", kWrenchAxisNames[k]), c.model_stiffness(k, k),
                    fe.stiffness(k, k), first.stiffness(k, k) / fe.stiffness(k, k)});
  }
  for (const auto& [g, k] : c.dominant) {
    rows.push_back({fmt::format("gauge {} {}", g, kWrenchAxisNames[k]), c.model_gauge_strain(g, k),
                    fe.gauge_strain(g, k), first.gauge_strain(g, k) / fe.gauge_strain(g, k)});
  }
  return rows;
}

/// Bars of model/FE per figure around 1 with the ±10 % band of the acceptance.
void RatioChart(std::ostream& o, const std::vector<RatioRow>& rows) {
  const int w = 900, h = 260, left = 50, bottom = 230;
  const double lo = 0.8, hi = 1.2;
  auto y = [&](double r) { return bottom - (std::clamp(r, lo, hi) - lo) / (hi - lo) * 210; };
  o << fmt::format("<svg xmlns='http://www.w3.org/2000/svg' width='{}' height='{}'>", w, h)
    << fmt::format("<rect x='{}' y='{:.1f}' width='{}' height='{:.1f}' fill='#e6f4e6'/>", left,
                   y(1.1), w - left - 10, y(0.9) - y(1.1));
  for (double r : {0.8, 0.9, 1.0, 1.1, 1.2}) {
    o << fmt::format(
        "<line x1='{}' y1='{:.1f}' x2='{}' y2='{:.1f}' stroke='#999' stroke-dasharray='{}'/>"
        "<text x='4' y='{:.1f}' font-size='11' font-family='sans-serif'>{:.2f}</text>",
        left, y(r), w - 10, y(r), r == 1.0 ? "0" : "3,3", y(r) + 4, r);
  }
  const double step = static_cast<double>(w - left - 20) / static_cast<double>(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double r = rows[i].model / rows[i].fe;
    const double x = left + 5 + step * static_cast<double>(i);
    const bool stiff = i < 6;
    o << fmt::format(
        "<rect x='{:.1f}' y='{:.1f}' width='{:.1f}' height='{:.1f}' fill='{}'><title>{} "
        "{:.3f}</title></rect>",
        x, std::min(y(r), y(1.0)), std::max(1.0, 0.8 * step), std::abs(y(r) - y(1.0)) + 1,
        stiff ? "#1f5fa8" : "#d9822b", rows[i].label, r);
  }
  o << fmt::format(
      "<text x='{}' y='252' font-size='11' font-family='sans-serif'>blue: stiffness diagonal "
      "(Fx … Mz); orange: dominant gauge strains in gauge order; green band: ±10 %</text></svg>\n",
      left);
}

/// The refined mesh's node sample, undeformed (grey) and deformed under Fz (coloured by the
/// strain magnitude), in the isometric view of the strain maps.
void DeformedShape(std::ostream& o, const FeSolution& s) {
  if (s.sample_m.empty()) return;
  double span = 1e-3, u_max = 0, e_max = 0;
  for (std::size_t i = 0; i < s.sample_m.size(); ++i) {
    span = std::max(span, s.sample_m[i].cwiseAbs().maxCoeff());
    u_max = std::max(u_max, s.sample_u[i].norm());
    e_max = std::max(e_max, s.sample_strain[i]);
  }
  const double k = 210.0 / span, magnify = u_max > 0 ? 0.2 * span / u_max : 0;
  auto px = [&](const Eigen::Vector3d& v) { return 280 + k * (v.x() - 0.5 * v.y()); };
  auto py = [&](const Eigen::Vector3d& v) { return 250 - k * (v.z() + 0.35 * v.y()); };
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='560' height='500'><rect width='560' "
       "height='500' fill='#fff' stroke='#999'/>\n";
  for (const Eigen::Vector3d& p : s.sample_m) {
    o << fmt::format("<circle cx='{:.1f}' cy='{:.1f}' r='0.8' fill='#ccc'/>", px(p), py(p));
  }
  for (std::size_t i = 0; i < s.sample_m.size(); ++i) {
    const Eigen::Vector3d q = s.sample_m[i] + magnify * s.sample_u[i];
    const double f = e_max > 0 ? s.sample_strain[i] / e_max : 0;
    o << fmt::format("<circle cx='{:.1f}' cy='{:.1f}' r='1.3' fill='rgb({},{},{})'/>", px(q), py(q),
                     static_cast<int>(255 * f), static_cast<int>(90 + 110 * (1 - f)),
                     static_cast<int>(200 * (1 - f)));
  }
  o << fmt::format(
      "<text x='8' y='476' font-size='11' font-family='sans-serif'>FE nodes (sample of {}): grey "
      "undeformed; coloured: deformed under Fz,</text><text x='8' y='490' font-size='11' "
      "font-family='sans-serif'>displacement ×{:.3g}; colour |strain| (blue 0 … red largest)</text>"
      "</svg>\n",
      s.sample_m.size(), magnify);
}

}  // namespace

void WriteFeCheckSection(std::ostream& o, const std::string& id, const FeCheck& c) {
  o << "<h2>FE check of " << id
    << "</h2>\n<p>Which figures come from which model: capacities, "
       "resolution, natural frequencies, stiffness and gauge strains everywhere else on this "
       "page come from the <b>Timoshenko frame model</b> (beams with shear deformation, plate "
       "factor for wide leaves, rigid hub/rim/stages, clamped member ends). The <b>FE</b> "
       "column is a solid model of the same members (gmsh, 20-node hexahedra, CalculiX) under "
       "the same idealisations: member ends on rigid bodies, the ground clamped, the wrench "
       "on the platform's reference node. The ratio shows what beam theory leaves out inside "
       "the members; hub, rim and joint compliance are outside both.</p>\n";
  if (c.meshes.empty()) {
    o << "<p>No FE solution: " << c.note << "</p>\n";
    return;
  }
  const std::vector<RatioRow> rows = Rows(c);
  RatioChart(o, rows);
  DeformedShape(o, c.meshes.back());
  o << "<p>";
  for (std::size_t i = 0; i < c.meshes.size(); ++i) {
    o << fmt::format("mesh {}: element size {:.3g} mm, {} layers, {} nodes, {:.1f} s. ", i + 1,
                     1e3 * c.meshes[i].element_size_m, c.meshes[i].layers, c.meshes[i].nodes,
                     c.meshes[i].seconds);
  }
  o << fmt::format("Largest |model/FE − 1| (refined mesh): <b id='fe-worst'>{:.3f}</b>.</p>\n",
                   WorstFeDeviation(c));
  o << "<table><tr><th>figure</th><th>model</th><th>FE</th><th>model/FE</th><th>mesh 1 / mesh "
       "2</th></tr>\n";
  for (const RatioRow& r : rows) {
    o << fmt::format(
        "<tr><td>{}</td><td>{:.4g}</td><td>{:.4g}</td><td>{:.3f}</td><td>{:.4f}</td></tr>\n",
        r.label, r.model, r.fe, r.model / r.fe, r.mesh_change);
  }
  o << "</table><p>Stiffness in N/m and N·m/rad; gauge strain per N or N·m.</p>\n";
}

}  // namespace ftstack::sim::design
