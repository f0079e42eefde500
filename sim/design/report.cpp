#include "sim/design/report.hpp"

#include "measurement/html_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace ftstack::sim::design {
namespace {

/// A log-log plot area: data range [x0, x1] × [y0, y1] onto a w × h pixel box with margins.
struct LogPlot {
  double x0, x1, y0, y1;
  int w = 640, h = 440, ml = 70, mr = 20, mt = 20, mb = 50;
  [[nodiscard]] double X(double v) const {
    return ml +
           (w - ml - mr) * (std::log10(v) - std::log10(x0)) / (std::log10(x1) - std::log10(x0));
  }
  [[nodiscard]] double Y(double v) const {
    return h - mb -
           (h - mt - mb) * (std::log10(v) - std::log10(y0)) / (std::log10(y1) - std::log10(y0));
  }
  [[nodiscard]] bool Inside(double x, double y) const {
    return x >= x0 && x <= x1 && y >= y0 && y <= y1 && std::isfinite(x) && std::isfinite(y);
  }
  void Axes(std::ostream& o, const std::string& xl, const std::string& yl) const {
    o << fmt::format(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{}' height='{}' "
        "font-family='sans-serif' font-size='11'>\n",
        w, h);
    o << fmt::format("<rect x='{}' y='{}' width='{}' height='{}' fill='#fcfcfc' stroke='#444'/>\n",
                     ml, mt, w - ml - mr, h - mt - mb);
    for (int e = static_cast<int>(std::ceil(std::log10(x0))); e <= std::log10(x1); ++e) {
      const double px = X(std::pow(10.0, e));
      o << fmt::format(
          "<line x1='{0:.1f}' x2='{0:.1f}' y1='{1}' y2='{2}' stroke='#ddd'/>"
          "<text x='{0:.1f}' y='{3}' text-anchor='middle'>1e{4}</text>\n",
          px, mt, h - mb, h - mb + 15, e);
    }
    for (int e = static_cast<int>(std::ceil(std::log10(y0))); e <= std::log10(y1); ++e) {
      const double py = Y(std::pow(10.0, e));
      o << fmt::format(
          "<line x1='{0}' x2='{1}' y1='{2:.1f}' y2='{2:.1f}' stroke='#ddd'/>"
          "<text x='{3}' y='{4:.1f}' text-anchor='end'>1e{5}</text>\n",
          ml, w - mr, py, ml - 5, py + 4, e);
    }
    o << fmt::format("<text x='{}' y='{}' text-anchor='middle'>{}</text>\n", (ml + w - mr) / 2,
                     h - 12, HtmlEscape(xl));
    o << fmt::format(
        "<text transform='translate(16,{}) rotate(-90)' text-anchor='middle'>{}</text>\n",
        (mt + h - mb) / 2, HtmlEscape(yl));
  }
};

const char* FamilyColour(const std::string& f) { return f == "guided" ? "#1f5fbf" : "#b05a00"; }

void CatalogueScatter(std::ostream& o, const Catalog& cat, const Trend& t,
                      const std::vector<Candidate>& ds, const Requirement* req) {
  const LogPlot p{1, 1e5, 0.01, 1e5};
  p.Axes(o, "Fxy range (N)", "Txy range (N·m)");
  for (const Candidate& c : ds) {
    const double fx = c.figures.capacity.head<2>().minCoeff();
    if (!p.Inside(fx, c.figures.tilt_capacity_nm)) continue;
    o << fmt::format("<rect x='{:.1f}' y='{:.1f}' width='4' height='4' fill='{}' opacity='{}'/>\n",
                     p.X(fx) - 2, p.Y(c.figures.tilt_capacity_nm) - 2, FamilyColour(c.model.family),
                     c.pareto ? 0.9 : 0.25);
  }
  const double a = p.x0, b = p.x1;
  o << fmt::format(
      "<line x1='{:.1f}' y1='{:.1f}' x2='{:.1f}' y2='{:.1f}' stroke='#c00' "
      "stroke-width='2' stroke-dasharray='6,3'/>\n",
      p.X(a), p.Y(t.coefficient * std::pow(a, t.exponent)), p.X(b),
      p.Y(t.coefficient * std::pow(b, t.exponent)));
  for (const CatalogRow& r : cat.rows) {
    if (!p.Inside(r.fxy_n, r.txy_nm)) continue;
    // Marker size: resolution as a fraction of the range (1:100 → 9 px … 1:10000 → 3 px).
    double rad = 4;
    if (std::isfinite(r.res_fxy_n)) {
      rad = std::clamp(3.0 + 3.0 * (std::log10(r.res_fxy_n / r.fxy_n) + 4.0), 2.0, 12.0);
    }
    const bool conf = r.fxy_confirmed && r.txy_confirmed;
    o << fmt::format(
        "<circle cx='{:.1f}' cy='{:.1f}' r='{:.1f}' fill='{}' stroke='#222'>"
        "<title>{} {} {}</title></circle>\n",
        p.X(r.fxy_n), p.Y(r.txy_nm), rad, conf ? "#333" : "none", HtmlEscape(r.vendor),
        HtmlEscape(r.model), HtmlEscape(r.calibration));
  }
  if (req != nullptr && req->peak(0) > 0) {
    o << fmt::format(
        "<path d='M{0:.1f},{1:.1f} m-7,0 l14,0 m-7,-7 l0,14' stroke='#0a0' "
        "stroke-width='3'/><text x='{2:.1f}' y='{1:.1f}' fill='#070'>{3}</text>\n",
        p.X(req->peak(0)), p.Y(req->peak(3)), p.X(req->peak(0)) + 9, HtmlEscape(req->name));
  }
  o << "</svg>\n";
}

void ParetoPlot(std::ostream& o, const std::vector<Candidate>& ds) {
  const LogPlot p{1e-4, 10, 0.1, 1e5};
  p.Axes(o, "noise-limited force resolution (N, 1σ)", "tilt capacity Mxy (N·m)");
  for (const Candidate& c : ds) {
    if (!p.Inside(c.figures.force_resolution_n, c.figures.tilt_capacity_nm)) continue;
    o << fmt::format(
        "<circle cx='{:.1f}' cy='{:.1f}' r='{}' fill='{}' opacity='{}' stroke='{}'/>\n",
        p.X(c.figures.force_resolution_n), p.Y(c.figures.tilt_capacity_nm), c.pareto ? 4 : 2.5,
        FamilyColour(c.model.family), c.pareto ? 0.95 : 0.3, c.check.met() ? "#0a0" : "none");
  }
  o << fmt::format(
      "<line x1='{0:.1f}' x2='{0:.1f}' y1='20' y2='390' stroke='#0a0' "
      "stroke-dasharray='4,3'/><line x1='70' x2='620' y1='{1:.1f}' y2='{1:.1f}' "
      "stroke='#0a0' stroke-dasharray='4,3'/>\n",
      p.X(kGoalForceResolutionN), p.Y(280.0));
  o << "</svg>\n";
}

/// Isometric view of the body, each segment coloured by |strain| / allowable under `loads`.
void StrainMap(std::ostream& o, const Candidate& c, const LoadSet& loads) {
  double span = 1e-3;
  for (const SketchSegment& s : c.model.sketch)
    span = std::max({span, s.a.cwiseAbs().maxCoeff(), s.b.cwiseAbs().maxCoeff()});
  const double k = 120.0 / span;
  auto px = [&](const Eigen::Vector3d& v) { return 160 + k * (v.x() - 0.5 * v.y()); };
  auto py = [&](const Eigen::Vector3d& v) { return 140 - k * (v.z() + 0.35 * v.y()); };
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='320' height='280'>"
       "<rect width='320' height='280' fill='#fff' stroke='#999'/>\n";
  const double allow = c.model.material.allowable_gauge_strain;
  for (const SketchSegment& s : c.model.sketch) {
    const int n = static_cast<int>(s.stations.size());
    for (int i = 0; i + 1 < n; ++i) {
      double e = 0;
      for (int j : {i, i + 1}) {
        for (const Row6& r : s.stations[static_cast<std::size_t>(j)]) e = std::max(e, loads.Max(r));
      }
      const double u = std::clamp(e / allow, 0.0, 1.5) / 1.5;
      const Eigen::Vector3d p = s.a + (s.b - s.a) * (i / (n - 1.0));
      const Eigen::Vector3d q = s.a + (s.b - s.a) * ((i + 1) / (n - 1.0));
      o << fmt::format(
          "<line x1='{:.1f}' y1='{:.1f}' x2='{:.1f}' y2='{:.1f}' stroke='rgb({},{},60)' "
          "stroke-width='5' stroke-linecap='round'/>\n",
          px(p), py(p), px(q), py(q), static_cast<int>(255 * u), static_cast<int>(200 * (1 - u)));
    }
  }
  o << "<text x='8' y='270' font-size='11' font-family='sans-serif'>colour: |strain| / allowable "
       "(green 0 … red ≥ 1.5)</text></svg>\n";
}

void CapacityTable(std::ostream& o, const Candidate& c) {
  const char* ax[6] = {"Fx N", "Fy N", "Fz N", "Mx N·m", "My N·m", "Mz N·m"};
  o << "<table><tr><th></th>";
  for (const char* a : ax) o << "<th>" << a << "</th>";
  o << "</tr><tr><td>capacity</td>";
  for (int k = 0; k < 6; ++k) {
    o << fmt::format("<td>{:.4g} <small>{}</small></td>", c.figures.capacity(k),
                     ToString(c.figures.binding[static_cast<std::size_t>(k)]));
  }
  o << "</tr><tr><td>resolution 1σ</td>";
  for (int k = 0; k < 6; ++k) o << fmt::format("<td>{:.3g}</td>", c.figures.resolution(k));
  o << "</tr><tr><td>stiffness</td>";
  for (int k = 0; k < 6; ++k) o << fmt::format("<td>{:.3g}</td>", c.figures.stiffness(k, k));
  o << "</tr></table>\n";
  o << fmt::format(
      "<p>combined-load rule ×{:.3f}; overload margin to yield {:.2f}×; condition "
      "number {:.3g}; first natural frequency {:.0f} Hz</p>\n",
      c.figures.combined_scale, c.figures.overload_margin, c.figures.condition_number,
      c.figures.natural_hz(0));
}

std::vector<const Candidate*> Showcase(const std::vector<Candidate>& ds, const Requirement* req) {
  std::vector<const Candidate*> out;
  for (const std::string fam : {"guided", "hub-spoke"}) {
    const Candidate* best = nullptr;
    for (const Candidate& c : ds) {
      if (c.model.family != fam) continue;
      // Requirement: the finest force resolution among designs that meet it, else the closest.
      auto score = [&](const Candidate& x) {
        if (req == nullptr) return -x.figures.tilt_capacity_nm;
        return x.check.met() ? x.figures.force_resolution_n : 1e6 + x.check.worst();
      };
      if (best == nullptr || score(c) < score(*best)) best = &c;
    }
    if (best != nullptr) out.push_back(best);
  }
  return out;
}

}  // namespace

void WriteDesignReport(std::ostream& o, const std::vector<Candidate>& ds, const Catalog& cat,
                       const Requirement* req, const DesignOptions& opt, const FeCheck* fe,
                       const std::string& fe_id) {
  const Trend t = FitTrend(cat, true);
  const Trend all = FitTrend(cat, false);
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>ftsim design</title><style>"
       "body{font-family:sans-serif;margin:20px;max-width:1150px}table{border-collapse:collapse;"
       "font-size:12px}td,th{border:1px solid #bbb;padding:2px 5px}pre{background:#f4f4f4;"
       "padding:8px;font-size:11px;white-space:pre-wrap}.pair{display:flex;gap:16px;flex-wrap:wrap}"
       "</style></head><body>\n<h1>Sensor-body design explorer</h1>\n";
  std::ostringstream text;
  PrintAssumptions(text, opt, Readout{});
  if (req != nullptr) {
    (void)PrintRequirementVerdict(text, ds, *req, 8);
    PrintGoal(text, ds, *req);
  }
  o << "<pre>" << HtmlEscape(text.str()) << "</pre>\n";
  o << "<h2>Catalogue: moment range against force range</h2>\n<div class='pair'><div>";
  CatalogueScatter(o, cat, t, ds, req);
  o << fmt::format(
      "</div><div style='max-width:460px;font-size:13px'><p>Circles: {} catalogue rows ({}), "
      "filled where Fxy and Txy are confirmed; marker size grows with resolution/range (coarser = "
      "larger). Red dashed line: least-squares fit in log space over the {} confirmed rows: "
      "T<sub>xy</sub> = {:.4g}·F<sub>xy</sub><sup>{:.3f}</sup>; exponent "
      "<b id='trend-exponent'>{:.3f}</b> (all {} rows with values, confirmed or not: {:.3f}).</p>"
      "<p>Squares: swept designs (orange hub-spoke, blue guided; solid = Pareto front) at their "
      "per-axis Fxy and tilt capacities. Green cross: the requirement.</p><p>Rows in the fit: ",
      cat.rows.size(), HtmlEscape(cat.origin), t.n, t.coefficient, t.exponent, t.exponent, all.n,
      all.exponent);
  for (const CatalogRow* r : t.used)
    o << HtmlEscape(r->vendor + " " + r->model + " " + r->calibration) << "; ";
  o << "</p></div></div>\n<h2>Pareto front: tilt capacity against force resolution</h2>\n";
  ParetoPlot(o, ds);
  o << "<p>Green dashed: 0.1 N resolution and 280 N·m tilting (the goal); green rims: designs "
       "that meet the requirement.</p>\n<h2>Pareto designs</h2>\n";
  std::vector<const Candidate*> front;
  for (const Candidate& c : ds) {
    if (c.pareto) front.push_back(&c);
  }
  std::sort(front.begin(), front.end(), [](const Candidate* a, const Candidate* b) {
    return a->figures.force_resolution_n < b->figures.force_resolution_n;
  });
  const std::size_t shown = std::min<std::size_t>(front.size(), 30);
  o << fmt::format("<p>{} designs on the front; the {} with the finest force resolution:</p>",
                   front.size(), shown);
  o << "<table><tr><th>id</th><th>family"
       "</th><th>Fxy cap N</th><th>Fz cap N</th><th>Mxy cap N·m</th><th>Mz cap N·m</th><th>force "
       "res N</th><th>min lateral k N/m</th><th>meets</th></tr>\n";
  for (std::size_t i = 0; i < shown; ++i) {
    const Candidate& c = *front[i];
    const DesignFigures& f = c.figures;
    o << fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{:.4g}</td><td>{:.4g}</td><td>{:.4g}</td>"
        "<td>{:.4g}</td><td>{:.3g}</td><td>{:.3g}</td><td>{}</td></tr>\n",
        c.id, c.model.family, f.capacity.head<2>().minCoeff(), f.capacity(2), f.tilt_capacity_nm,
        f.capacity(5), f.force_resolution_n, f.stiffness.diagonal().head<3>().minCoeff(),
        req == nullptr ? "-" : (c.check.met() ? "yes" : "no"));
  }
  o << "</table>\n<h2>Selected designs: strain maps and capacities</h2>\n";
  for (const Candidate* c : Showcase(ds, req)) {
    o << "<h3>" << HtmlEscape(c->id + " (" + c->model.family + ", " + c->model.material.name + ")")
      << "</h3><p>";
    for (const auto& [k, v] : c->model.parameters) o << fmt::format("{}={:.4g} ", HtmlEscape(k), v);
    o << "</p><div class='pair'><div>";
    const EnvelopeLoads rated(c->figures.capacity.head<2>().minCoeff(), c->figures.capacity(2),
                              c->figures.tilt_capacity_nm, c->figures.capacity(5));
    StrainMap(o, *c, req != nullptr ? *req->loads : static_cast<const LoadSet&>(rated));
    o << "</div><div>";
    CapacityTable(o, *c);
    if (req != nullptr) {
      o << fmt::format(
          "<p>under {}: utilisation yield {:.2f}, gauge range {:.2f}, buckling {:.2f} "
          "→ {}</p>",
          HtmlEscape(req->name), c->check.yield, c->check.gauge, c->check.buckling,
          c->check.met() ? "carries it" : "binding: " + c->check.binding());
    }
    o << "</div></div>\n";
  }
  if (fe != nullptr) WriteFeCheckSection(o, fe_id, *fe);
  o << "</body></html>\n";
}

}  // namespace ftstack::sim::design
