#include "calibration/fit/fit_report.hpp"

#include "measurement/html_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace ftstack::cal {
namespace {

const char* const kAxes[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
const char* const kUnits[6] = {"N", "N", "N", "N·m", "N·m", "N·m"};
const char* const kColors[6] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"};

std::string Fmt(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

/// "Nice" axis limit ≥ v.
double NiceCeil(double v) {
  if (!(v > 0)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * p >= v) return m * p;
  }
  return 10.0 * p;
}

/// Grouped bar chart of two series per axis.
std::string BarChart(const std::array<double, 6>& a, const std::array<double, 6>& b,
                     const std::string& la, const std::string& lb, const std::string& ylabel) {
  const double w = 560;
  const double h = 260;
  const double l = 60;
  const double t = 20;
  const double pw = w - l - 20;
  const double ph = h - t - 50;
  double top = 0;
  for (int i = 0; i < 6; ++i)
    top = std::max({top, a[static_cast<std::size_t>(i)], b[static_cast<std::size_t>(i)]});
  top = NiceCeil(top * 1.05);
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << w << "' height='" << h
    << "' font-family='sans-serif' font-size='11'>";
  for (int g = 0; g <= 4; ++g) {
    const double y = t + ph - ph * g / 4.0;
    o << "<line x1='" << l << "' x2='" << l + pw << "' y1='" << y << "' y2='" << y
      << "' stroke='#ddd'/><text x='" << l - 4 << "' y='" << y + 4 << "' text-anchor='end'>"
      << Fmt("%.3g", top * g / 4.0) << "</text>";
  }
  const double slot = pw / 6.0;
  for (int i = 0; i < 6; ++i) {
    const double x0 = l + slot * i + slot * 0.15;
    const double bw = slot * 0.35;
    const double ha = ph * a[static_cast<std::size_t>(i)] / top;
    const double hb = ph * b[static_cast<std::size_t>(i)] / top;
    o << "<rect x='" << x0 << "' y='" << t + ph - ha << "' width='" << bw << "' height='" << ha
      << "' fill='#1f77b4'/><rect x='" << x0 + bw << "' y='" << t + ph - hb << "' width='" << bw
      << "' height='" << hb << "' fill='#ff7f0e'/><text x='" << x0 + bw << "' y='" << t + ph + 15
      << "' text-anchor='middle'>" << kAxes[i] << "</text>";
  }
  o << "<line x1='" << l << "' x2='" << l << "' y1='" << t << "' y2='" << t + ph
    << "' stroke='#000'/><line x1='" << l << "' x2='" << l + pw << "' y1='" << t + ph << "' y2='"
    << t + ph << "' stroke='#000'/>";
  o << "<text x='14' y='" << t + ph / 2 << "' transform='rotate(-90 14 " << t + ph / 2
    << ")' text-anchor='middle'>" << ylabel << "</text>";
  o << "<rect x='" << l + 10 << "' y='" << h - 18
    << "' width='10' height='10' fill='#1f77b4'/><text x='" << l + 24 << "' y='" << h - 9 << "'>"
    << la << "</text><rect x='" << l + 200 << "' y='" << h - 18
    << "' width='10' height='10' fill='#ff7f0e'/><text x='" << l + 214 << "' y='" << h - 9 << "'>"
    << lb << "</text></svg>";
  return o.str();
}

/// Scatter of every axis's held-out residual (% rated) against wrench component `comp`.
std::string ResidualPlot(const FitResult& fit, const RigData& d, int comp) {
  const double w = 380;
  const double h = 250;
  const double l = 50;
  const double t = 22;
  const double pw = w - l - 12;
  const double ph = h - t - 40;
  const Eigen::Index rows = d.wrench.rows();
  const Eigen::Index stride = std::max<Eigen::Index>(1, rows / 800);
  const double rc = fit.rated[static_cast<std::size_t>(comp)];
  double xmax = 0;
  double ymax = 0;
  for (Eigen::Index i = 0; i < rows; i += stride) {
    xmax = std::max(xmax, std::fabs(d.wrench(i, comp)) / rc * 100);
    for (int a = 0; a < 6; ++a) {
      ymax = std::max(ymax, std::fabs(fit.heldout_residual(i, a)) /
                                fit.rated[static_cast<std::size_t>(a)] * 100);
    }
  }
  xmax = NiceCeil(std::max(xmax, 1e-9));
  ymax = NiceCeil(std::max(ymax, 1e-9));
  auto px = [&](double v) { return l + pw * (v / xmax + 1) / 2; };
  auto py = [&](double v) { return t + ph * (1 - (v / ymax + 1) / 2); };
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << w << "' height='" << h
    << "' font-family='sans-serif' font-size='10'>";
  o << "<text x='" << l + pw / 2 << "' y='14' text-anchor='middle' font-size='12'>residual vs "
    << kAxes[comp] << "</text>";
  o << "<rect x='" << l << "' y='" << t << "' width='" << pw << "' height='" << ph
    << "' fill='none' stroke='#000'/>";
  o << "<line x1='" << l << "' x2='" << l + pw << "' y1='" << py(0) << "' y2='" << py(0)
    << "' stroke='#999'/>";
  for (double v : {-ymax, ymax}) {
    o << "<text x='" << l - 3 << "' y='" << py(v) + 4 << "' text-anchor='end'>" << Fmt("%.3g", v)
      << "</text>";
  }
  for (double v : {-xmax, 0.0, xmax}) {
    o << "<text x='" << px(v) << "' y='" << t + ph + 12 << "' text-anchor='middle'>"
      << Fmt("%.3g", v) << "</text>";
  }
  o << "<text x='" << l + pw / 2 << "' y='" << h - 6 << "' text-anchor='middle'>" << kAxes[comp]
    << " load, % of rated</text>";
  o << "<text x='10' y='" << t + ph / 2 << "' transform='rotate(-90 10 " << t + ph / 2
    << ")' text-anchor='middle'>error, % of rated</text>";
  for (int a = 0; a < 6; ++a) {
    o << "<g fill='" << kColors[a] << "' fill-opacity='0.5'>";
    for (Eigen::Index i = 0; i < rows; i += stride) {
      o << "<circle cx='" << Fmt("%.1f", px(d.wrench(i, comp) / rc * 100)) << "' cy='"
        << Fmt("%.1f",
               py(fit.heldout_residual(i, a) / fit.rated[static_cast<std::size_t>(a)] * 100))
        << "' r='1.3'/>";
    }
    o << "</g>";
  }
  o << "</svg>";
  return o.str();
}

std::string Legend() {
  std::ostringstream o;
  o << "<p>";
  for (int a = 0; a < 6; ++a) {
    o << "<span style='color:" << kColors[a] << "'>&#9679; " << kAxes[a] << " error</span> &nbsp; ";
  }
  o << "</p>";
  return o.str();
}

nlohmann::json MarginJson(const ChoiceMargin& m) {
  if (m.complex.empty()) return nullptr;
  return {{"simpler", m.simpler},
          {"complex", m.complex},
          {"margin", m.margin},
          {"se", m.se},
          {"simpler_score", m.simpler_score}};
}

/// "lower by 4.3 % of 1.2e-05 ± 7.1 % (0.61 SE)": a margin relative to the simpler score.
std::string MarginText(const ChoiceMargin& m) {
  const double rel = m.simpler_score > 0 ? m.margin / m.simpler_score * 100 : 0.0;
  const double rel_se = m.simpler_score > 0 ? m.se / m.simpler_score * 100 : 0.0;
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "score lower by %.3g %% +- %.3g %% (margin %.3g, SE %.3g, %.2f SE)", rel, rel_se,
                m.margin, m.se, m.se > 0 ? m.margin / m.se : 0.0);
  return buf;
}

}  // namespace

std::string ChoiceLine(const FitResult& fit) {
  std::string s = "choice (one-standard-error rule, paired over " + std::to_string(fit.folds) +
                  " folds): " + ToString(fit.kind) + " lambda=" + Fmt("%g", fit.lambda);
  if (fit.over_simplest.complex.empty()) {
    s += ", the simplest candidate";
  } else {
    s += " over " + fit.over_simplest.simpler + ": " + MarginText(fit.over_simplest);
  }
  s += "\n";
  if (!fit.challenger.complex.empty()) {
    s += "  closest not taken: " + fit.challenger.complex + ": " + MarginText(fit.challenger) +
         " (needs > 1 SE)\n";
  }
  return s;
}

CalFile CalFileFromFit(const FitResult& fit, const hal::AdcInfo& adc, const std::string& serial,
                       const std::string& date) {
  CalFile f;
  f.serial = serial;
  f.date = date;
  f.source = "fit";
  f.cal = fit.cal;
  f.adc = adc;
  f.adc.channel_count = fit.cal.channel_count;
  f.rated = fit.rated;
  f.uncertainty = fit.heldout_rms_si;
  f.extra["fit"] = {{"model", ToString(fit.kind)},
                    {"lambda", fit.lambda},
                    {"folds", fit.folds},
                    {"rows", fit.rows},
                    {"blocks", fit.block_count},
                    {"block_method", fit.block_method},
                    {"validation", fit.validation},
                    {"suspect_blocks", fit.suspect_blocks},
                    {"robust", fit.robust},
                    {"choice_rule", "one standard error of paired per-fold differences"},
                    {"choice_over_simplest", MarginJson(fit.over_simplest)},
                    {"choice_challenger", MarginJson(fit.challenger)},
                    {"robust_margin", MarginJson(fit.robust_margin)},
                    {"lambda_at_bound", fit.lambda_at_bound},
                    {"worst_group", fit.groups.empty() ? -1 : fit.groups.front().block},
                    {"worst_group_rms_pct", fit.groups.empty() ? 0.0 : fit.groups.front().rms_pct},
                    {"heldout_rms", fit.heldout_rms_si},
                    {"heldout_p95", fit.heldout_p95_si},
                    {"fit_uncertainty", fit.fit_uncertainty_si},
                    {"load_condition", fit.load_condition},
                    {"design_condition", fit.design_condition}};
  return f;
}

std::string FitSummary(const FitResult& fit, const fw::LoadReport& fixed) {
  std::ostringstream o;
  o << "model: " << ToString(fit.kind) << ", ridge lambda " << Fmt("%g", fit.lambda)
    << " (chosen by " << fit.folds << "-fold cross-validation holding out whole " << fit.validation
    << ", " << fit.rows << " rows)\n";
  o << ChoiceLine(fit);
  if (fit.lambda_at_bound)
    o << "warning: lambda is the largest tried; the penalty is not resolved by the data\n";
  o << "condition number: load set " << Fmt("%.3g", fit.load_condition) << ", design "
    << Fmt("%.3g", fit.design_condition) << "\n";
  o << "axis   rated        held-out RMS        held-out 95%        fit unc.    fixed-pt worst\n";
  for (std::size_t a = 0; a < 6; ++a) {
    const double r = fit.rated[a];
    char line[200];
    std::snprintf(line, sizeof line,
                  "%-4s %8.4g %-3s %9.3g (%7.4f%%) %9.3g (%7.4f%%) %10.3g %12.3g\n", kAxes[a], r,
                  kUnits[a], fit.heldout_rms_si[a], fit.heldout_rms_si[a] / r * 100,
                  fit.heldout_p95_si[a], fit.heldout_p95_si[a] / r * 100, fit.fit_uncertainty_si[a],
                  fixed.worst_case_error_si[a]);
    o << line;
  }
  o << "candidates (score = mean over validation units of mean over axes (error/rated)^2):\n";
  for (const CandidateScore& c : fit.candidates) {
    o << "  " << ToString(c.kind) << " lambda=" << Fmt("%g", c.lambda) << " features=" << c.features
      << " score=" << Fmt("%.4g", c.score) << "\n";
  }
  if (!fit.groups.empty()) {
    o << "held-out RMS per group (% of rated), worst first:";
    for (const BlockScore& g : fit.groups) {
      o << " g" << g.block << " " << Fmt("%.3g%%", g.rms_pct) << ";";
    }
    o << "\n";
  }
  if (!fit.suspect_blocks.empty()) {
    o << "suspect blocks (held-out error an outlier: recorded badly?):";
    for (const int b : fit.suspect_blocks) o << " #" << b;
    o << "; down-weighted fit " << (fit.robust ? "used" : "not used") << ": "
      << MarginText(fit.robust_margin) << "\n";
  }
  o << "worst blocks (RMS % of rated):";
  for (std::size_t i = 0; i < std::min<std::size_t>(5, fit.blocks.size()); ++i) {
    o << " #" << fit.blocks[i].block << " t=" << Fmt("%.2f", fit.blocks[i].t_start_s) << "s "
      << Fmt("%.3g%%", fit.blocks[i].rms_pct) << ";";
  }
  o << "\n";
  return o.str();
}

void WriteFitReport(const std::string& path, const FitResult& fit, const RigData& d,
                    const fw::LoadReport& fixed, const std::string& title) {
  std::ofstream out(path);
  if (!out) throw CalFileError(path + ": cannot write the report");
  std::array<double, 6> rms_pct{};
  std::array<double, 6> p95_pct{};
  for (std::size_t a = 0; a < 6; ++a) {
    rms_pct[a] = fit.heldout_rms_si[a] / fit.rated[a] * 100;
    p95_pct[a] = fit.heldout_p95_si[a] / fit.rated[a] * 100;
  }
  out << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>Calibration fit: "
      << HtmlEscape(title)
      << "</title><style>body{font-family:sans-serif;margin:20px;max-width:1200px}"
      << "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px;"
      << "text-align:right}th{background:#eee}.plots svg{margin:4px}</style></head><body>";
  out << "<h1>Calibration fit: " << HtmlEscape(title) << "</h1>";
  out << "<p>Model <b>" << ToString(fit.kind) << "</b>, ridge &lambda; = " << Fmt("%g", fit.lambda)
      << ", chosen by " << fit.folds << "-fold cross-validation holding out whole "
      << HtmlEscape(fit.validation) << " (" << fit.block_count << " blocks found by "
      << HtmlEscape(fit.block_method) << ", " << fit.rows
      << " rows). Errors below are on <b>held-out</b> rows only.</p>";
  out << "<p>Condition number of the load set: <b>" << Fmt("%.3g", fit.load_condition)
      << "</b>; of the chosen model's standardised design: <b>" << Fmt("%.3g", fit.design_condition)
      << "</b>.</p>";
  out << "<table><tr><th>axis</th><th>rated</th><th>held-out RMS</th><th>% rated</th>"
      << "<th>held-out 95 %</th><th>% rated</th><th>fit (parameter) uncertainty</th>"
      << "<th>residual &sigma;</th><th>fixed-point worst case</th></tr>";
  for (std::size_t a = 0; a < 6; ++a) {
    out << "<tr><td>" << kAxes[a] << "</td><td>" << Fmt("%.4g ", fit.rated[a]) << kUnits[a]
        << "</td><td>" << Fmt("%.3g", fit.heldout_rms_si[a]) << "</td><td>"
        << Fmt("%.4f", rms_pct[a]) << "</td><td>" << Fmt("%.3g", fit.heldout_p95_si[a])
        << "</td><td>" << Fmt("%.4f", p95_pct[a]) << "</td><td>"
        << Fmt("%.3g", fit.fit_uncertainty_si[a]) << "</td><td>"
        << Fmt("%.3g", fit.residual_sigma_si[a]) << "</td><td>"
        << Fmt("%.3g", fixed.worst_case_error_si[a]) << "</td></tr>";
  }
  out << "</table>";
  out << "<h2>Held-out error per axis</h2>"
      << BarChart(rms_pct, p95_pct, "RMS", "95th percentile", "% of rated");
  out << "<h2>Held-out residuals against each wrench component</h2>" << Legend()
      << "<div class='plots'>";
  for (int c = 0; c < 6; ++c) out << ResidualPlot(fit, d, c);
  out << "</div>";
  // Held-out error per unit (validation group or block), worst first.
  const auto unit_table = [&](const char* heading, const char* unit,
                              const std::vector<BlockScore>& scores, std::size_t limit) {
    out << "<h2>" << heading << "</h2><table><tr><th>" << unit
        << "</th><th>t start (s)</th><th>t end (s)</th><th>rows</th><th>RMS error, % rated</th>";
    for (const char* a : kAxes) out << "<th>mean " << a << "</th>";
    out << "</tr>";
    for (std::size_t i = 0; i < std::min(limit, scores.size()); ++i) {
      const BlockScore& b = scores[i];
      out << "<tr><td>" << b.block << "</td><td>" << Fmt("%.3f", b.t_start_s) << "</td><td>"
          << Fmt("%.3f", b.t_end_s) << "</td><td>" << b.rows << "</td><td>"
          << Fmt("%.4f", b.rms_pct) << "</td>";
      for (double w : b.mean_wrench) out << "<td>" << Fmt("%.4g", w) << "</td>";
      out << "</tr>";
    }
    out << "</table>";
  };
  if (!fit.groups.empty()) {
    unit_table("Held-out error per validation group", "group", fit.groups, fit.groups.size());
  }
  unit_table("Worst blocks", "block", fit.blocks, 10);
  if (!fit.suspect_blocks.empty()) {
    out << "<p>Suspect blocks (held-out error over 3.5 robust &sigma; above the median block): ";
    for (const int b : fit.suspect_blocks) out << b << " ";
    out << "&mdash; down-weighted fit " << (fit.robust ? "used" : "not used (validated worse)")
        << ".</p>";
  }
  out << "<h2>Candidates</h2><table><tr><th>model</th><th>&lambda;</th><th>features</th>"
      << "<th>score</th>";
  for (const char* a : kAxes) out << "<th>RMS " << a << "</th>";
  out << "</tr>";
  for (const CandidateScore& c : fit.candidates) {
    const bool chosen = c.kind == fit.kind && c.lambda == fit.lambda;
    out << "<tr" << (chosen ? " style='font-weight:bold;background:#efe'" : "") << "><td>"
        << ToString(c.kind) << "</td><td>" << Fmt("%g", c.lambda) << "</td><td>" << c.features
        << "</td><td>" << Fmt("%.4g", c.score) << "</td>";
    for (double r : c.rms_si) out << "<td>" << Fmt("%.3g", r) << "</td>";
    out << "</tr>";
  }
  out << "</table></body></html>\n";
  if (!out) throw CalFileError(path + ": write failed");
}

}  // namespace ftstack::cal
