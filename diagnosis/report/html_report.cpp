#include "diagnosis/report/html_report.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "measurement/effect_vocabulary.hpp"
#include "measurement/html_text.hpp"
#include "measurement/wrench.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace ftstack::diag {
namespace {

std::string Num(double v, const char* f = "%.4g") {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

/// "a" or "a–b": the smallest and largest grid step of the bridges that have one, times k (mV/V).
std::string StepRange(const Eigen::VectorXd& step_mvv, double k) {
  double lo = 0.0;
  double hi = 0.0;
  for (Eigen::Index c = 0; c < step_mvv.size(); ++c) {
    if (step_mvv(c) <= 0) continue;
    lo = lo > 0 ? std::min(lo, step_mvv(c)) : step_mvv(c);
    hi = std::max(hi, step_mvv(c));
  }
  const std::string a = Num(k * lo, "%.3g");
  const std::string b = Num(k * hi, "%.3g");
  return a == b ? a : a + "–" + b;
}

/// One value, a list of per-channel values, or per channel a list ("b0: …; b1: …").
std::string Cell(const nlohmann::json& v) {
  if (v.is_number()) return Num(v.get<double>());
  if (v.is_array()) {
    const bool nested = !v.empty() && v[0].is_array();
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (nested) out += (i ? "; b" : "b") + std::to_string(i) + ": ";
      out += (i && !nested ? ", " : "") + Cell(v[i]);
    }
    return out;
  }
  return HtmlEscape(v.is_string() ? v.get<std::string>() : v.dump());
}

/// A parameter's spread across pieces of the record: "min … max (σ pieces); disagree", or "—".
std::string SpreadCell(const EffectFit& f, const std::string& key) {
  if (!f.spread.contains(key)) return "—";
  const auto& s = f.spread[key];
  if (!s.contains("min")) {
    return std::to_string(s["pieces"].get<int>()) + " resolved piece(s): no spread";
  }
  std::string h = Cell(s["min"]) + " … " + Cell(s["max"]) + " (± " + Cell(s["sigma"]) + " from " +
                  std::to_string(s["pieces"].get<int>()) + " pieces)";
  if (s["agree"].is_boolean() && !s["agree"].get<bool>()) h += " <b>pieces disagree</b>";
  return h;
}

/// The fitted parameters as a table: name, value, 1-σ uncertainty (curvature), the spread across
/// pieces of the record, unit and status as the engine typed them (`typed`: TypedParameters).
std::string ParamTable(const EffectFit& f, const nlohmann::json& typed) {
  if (f.params.empty()) return "";
  std::string h =
      "<table><tr><th>parameter</th><th>value</th><th>± 1σ (curvature)</th><th>across pieces of "
      "the record: min … max (± σ)</th><th>unit</th><th>range</th><th>status</th></tr>";
  for (const auto& [key, value] : f.params.items()) {
    const std::string sigma = f.sigma.contains(key) ? Cell(f.sigma[key]) : "—";
    std::string unit;
    std::string range = "—";
    std::string status = "—";
    for (const auto& p : typed) {
      if (p["key"] != key) continue;
      if (p["unit"].is_string()) unit = p["unit"].get<std::string>();
      if (p["range"].is_array()) range = Cell(p["range"][0]) + " … " + Cell(p["range"][1]);
      status = p["status"].get<std::string>();
    }
    h += "<tr><td>" + HtmlEscape(key) + "</td><td>" + Cell(value) + "</td><td>" + sigma +
         "</td><td>" + SpreadCell(f, key) + "</td><td>" + HtmlEscape(unit) + "</td><td>" + range +
         "</td><td>" + HtmlEscape(status) + "</td></tr>";
  }
  return h + "</table>";
}

/// Figures in a standard's terms (EffectFit::standard) as a table: figure, value, 1-σ, unit.
std::string StandardTable(const EffectFit& f) {
  if (!f.standard.contains("oiml_r60")) return "";
  const auto& o = f.standard["oiml_r60"];
  struct Row {
    const char* key;
    const char* label;
  };
  const Row rows[] = {
      {"creep_30min_pct", "OIML R 60 creep (30 min)"},
      {"creep_20_30min_pct", "OIML R 60 creep between 20 and 30 min"},
      {"dead_load_return_pct", "minimum dead-load output return (30 min after unloading)"}};
  std::string h = "<p>In OIML R 60's terms (load cells), per bridge, from the fitted model: " +
                  HtmlEscape(o.value("load", "")) +
                  ".</p><table><tr><th>figure</th><th>value</th><th>± 1σ</th><th>unit</th></tr>";
  for (const auto& row : rows) {
    if (!o.contains(row.key)) continue;
    const auto& u = o["uncertainty"];
    h += std::string("<tr><td>") + row.label + "</td><td>" + Cell(o[row.key]) + "</td><td>" +
         (u.contains(row.key) ? Cell(u[row.key]) : "—") + "</td><td>% of the load output</td></tr>";
  }
  return h + "</table>";
}

/// Nice tick values covering [lo, hi].
std::vector<double> Ticks(double lo, double hi, int want) {
  std::vector<double> t;
  if (!(hi > lo)) return t;
  const double raw = (hi - lo) / want;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-12 * std::fabs(hi); v += step)
    t.push_back(std::fabs(v) < step * 1e-9 ? 0.0 : v);
  return t;
}

/// Reduces a long line to min/max per pixel column, keeping order.
void Reduce(const PlotSeries& s, double x0, double x1, int cols, std::vector<double>* rx,
            std::vector<double>* ry) {
  if (s.x.size() <= static_cast<std::size_t>(cols) * 2 || s.points) {
    const std::size_t stride = s.points ? std::max<std::size_t>(1, s.x.size() / 4000) : 1;
    for (std::size_t i = 0; i < s.x.size(); i += stride) {
      rx->push_back(s.x[i]);
      ry->push_back(s.y[i]);
    }
    return;
  }
  int cur = -1;
  double mn = 0;
  double mx = 0;
  double xmn = 0;
  double xmx = 0;
  auto flush = [&] {
    if (cur < 0) return;
    if (xmn <= xmx) {
      rx->push_back(xmn);
      ry->push_back(mn);
      rx->push_back(xmx);
      ry->push_back(mx);
    } else {
      rx->push_back(xmx);
      ry->push_back(mx);
      rx->push_back(xmn);
      ry->push_back(mn);
    }
  };
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const int col = static_cast<int>((s.x[i] - x0) / (x1 - x0) * cols);
    if (col != cur) {
      flush();
      cur = col;
      mn = mx = s.y[i];
      xmn = xmx = s.x[i];
    } else {
      if (s.y[i] < mn) {
        mn = s.y[i];
        xmn = s.x[i];
      }
      if (s.y[i] > mx) {
        mx = s.y[i];
        xmx = s.x[i];
      }
    }
  }
  flush();
}

/// The excluded ranges (blue bands) and the marks (red lines) of a plot area [top, top + height].
template <class Px>
std::string SvgMarks(const PlotSpec& spec, Px px, double x0, double x1, int top, int height) {
  std::string o;
  for (const auto& [a, b] : spec.excluded) {
    if (b < x0 || a > x1) continue;
    const double xa = px(std::max(a, x0));
    const double xb = px(std::min(b, x1));
    o += "<rect x=\"" + Num(xa) + "\" y=\"" + std::to_string(top) + "\" width=\"" +
         Num(std::max(1.0, xb - xa)) + "\" height=\"" + std::to_string(height) +
         "\" fill=\"#9ec5f0\" opacity=\"0.6\"/>";
  }
  for (const double m : spec.marks) {
    if (m < x0 || m > x1) continue;
    o += "<line x1=\"" + Num(px(m)) + "\" x2=\"" + Num(px(m)) + "\" y1=\"" + std::to_string(top) +
         "\" y2=\"" + std::to_string(top + height) +
         "\" stroke=\"#e00\" stroke-width=\"1\" opacity=\"0.8\"/>";
  }
  return o;
}

/// The plotted x and y range of `series` (y in log10 for a log plot, padded by 5 %): x0, x1, y0,
/// y1.
std::array<double, 4> PlotRange(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  double x0 = std::numeric_limits<double>::infinity();
  double x1 = -x0;
  double y0 = x0;
  double y1 = -x0;
  auto ty = [&](double v) { return spec.log_y ? std::log10(std::max(v, 1e-300)) : v; };
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, ty(s.y[i]));
      y1 = std::max(y1, ty(s.y[i]));
    }
  }
  if (!(x1 > x0)) {
    x0 = 0;
    x1 = 1;
  }
  if (!(y1 > y0)) {
    y0 = (std::isfinite(y0) ? y0 : 0) - 1;
    y1 = y0 + 2;
  }
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad;
  y1 += pad;
  return {x0, x1, y0, y1};
}

}  // namespace

std::string SvgPlot(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  const int ml = 70;
  const int mr = 20;
  const int mt = 28;
  const int mb = 42;
  const int pw = spec.width - ml - mr;
  const int ph = spec.height - mt - mb;
  auto ty = [&](double v) { return spec.log_y ? std::log10(std::max(v, 1e-300)) : v; };
  const auto [x0, x1, y0, y1] = PlotRange(spec, series);
  auto px = [&](double x) { return ml + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return mt + (1.0 - (ty(y) - y0) / (y1 - y0)) * ph; };
  auto pyl = [&](double yl) { return mt + (1.0 - (yl - y0) / (y1 - y0)) * ph; };
  std::string o;
  o += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(spec.width) +
       "\" height=\"" + std::to_string(spec.height) +
       "\" font-family=\"sans-serif\" font-size=\"12\">";
  o += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>";
  o += "<text x=\"" + std::to_string(ml) + "\" y=\"18\" font-weight=\"bold\">" +
       HtmlEscape(spec.title) + "</text>";
  for (const auto& [a, b] : spec.spans) {
    const double xa = px(std::max(a, x0));
    const double xb = px(std::min(b, x1));
    o += "<rect x=\"" + Num(xa) + "\" y=\"" + std::to_string(mt) + "\" width=\"" +
         Num(std::max(1.0, xb - xa)) + "\" height=\"" + std::to_string(ph) +
         "\" fill=\"#f6d7a7\" opacity=\"0.6\"/>";
  }
  o += SvgMarks(spec, px, x0, x1, mt, ph);
  o += "<rect x=\"" + std::to_string(ml) + "\" y=\"" + std::to_string(mt) + "\" width=\"" +
       std::to_string(pw) + "\" height=\"" + std::to_string(ph) +
       "\" fill=\"none\" stroke=\"#444\"/>";
  for (double t : Ticks(x0, x1, 8)) {
    o += "<line x1=\"" + Num(px(t)) + "\" x2=\"" + Num(px(t)) + "\" y1=\"" +
         std::to_string(mt + ph) + "\" y2=\"" + std::to_string(mt + ph + 5) +
         "\" stroke=\"#444\"/>";
    o += "<text x=\"" + Num(px(t)) + "\" y=\"" + std::to_string(mt + ph + 18) +
         "\" text-anchor=\"middle\">" + Num(t) + "</text>";
  }
  for (double t : Ticks(y0, y1, 5)) {
    o += "<line x1=\"" + std::to_string(ml) + "\" x2=\"" + std::to_string(ml + pw) + "\" y1=\"" +
         Num(pyl(t)) + "\" y2=\"" + Num(pyl(t)) + "\" stroke=\"#ddd\"/>";
    o += "<text x=\"" + std::to_string(ml - 5) + "\" y=\"" + Num(pyl(t) + 4) +
         "\" text-anchor=\"end\">" + (spec.log_y ? Num(std::pow(10.0, t), "%.2g") : Num(t)) +
         "</text>";
  }
  o += "<text x=\"" + std::to_string(ml + pw / 2) + "\" y=\"" + std::to_string(spec.height - 6) +
       "\" text-anchor=\"middle\">" + HtmlEscape(spec.x_label) + "</text>";
  o += "<text transform=\"translate(14," + std::to_string(mt + ph / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + HtmlEscape(spec.y_label) + "</text>";
  int legend_x = ml + 10;
  for (const auto& s : series) {
    std::vector<double> rx;
    std::vector<double> ry;
    Reduce(s, x0, x1, pw, &rx, &ry);
    if (s.points) {
      o += "<g fill=\"" + s.color + "\" opacity=\"0.5\">";
      for (std::size_t i = 0; i < rx.size(); ++i) {
        o += "<circle cx=\"" + Num(px(rx[i]), "%.1f") + "\" cy=\"" + Num(py(ry[i]), "%.1f") +
             "\" r=\"1.5\"/>";
      }
      o += "</g>";
    } else {
      o += "<polyline fill=\"none\" stroke=\"" + s.color + "\" stroke-width=\"1\" points=\"";
      for (std::size_t i = 0; i < rx.size(); ++i) {
        o += Num(px(rx[i]), "%.1f") + "," + Num(py(ry[i]), "%.1f") + " ";
      }
      o += "\"/>";
    }
    if (!s.label.empty()) {
      o += "<rect x=\"" + std::to_string(legend_x) + "\" y=\"" + std::to_string(mt + 6) +
           "\" width=\"12\" height=\"4\" fill=\"" + s.color + "\"/>";
      o += "<text x=\"" + std::to_string(legend_x + 16) + "\" y=\"" + std::to_string(mt + 12) +
           "\">" + HtmlEscape(s.label) + "</text>";
      legend_x += 24 + 7 * static_cast<int>(s.label.size());
    }
  }
  o += "</svg>";
  return o;
}

/// The channel table and the load region carrying the excess.
std::string HtmlChannels(const Report& r) {
  const Context& cx = r.cx;
  std::string h;
  h += "<h2>Channels</h2><table><tr><th>channel</th><th>noise RMS</th><th>RMS before</th><th>RMS "
       "after</th><th>mismatch</th></tr>";
  for (int c = 0; c < cx.nc; ++c) {
    const double after = r.effects.empty() ? r.rms_before(c) : r.effects.back().rms_after(c);
    const bool mm = std::find(r.mismatch_channels.begin(), r.mismatch_channels.end(), c) !=
                    r.mismatch_channels.end();
    h += "<tr><td>b" + std::to_string(c) + "</td><td>" + Num(r.noise_rms(c)) + "</td><td>" +
         Num(r.rms_before(c)) + "</td><td>" + Num(after) + "</td><td>" + (mm ? "yes" : "") +
         "</td></tr>";
  }
  h += "</table>";
  if (!r.load_region.is_null() && r.load_region.contains("range")) {
    h += "<p>Load region carrying the excess: <b>" + r.load_region["component"].get<std::string>() +
         " " + r.load_region["sign"].get<std::string>() + "</b> between " +
         Num(r.load_region["range"][0].get<double>()) + " and " +
         Num(r.load_region["range"][1].get<double>()) + " (mean squared residual there " +
         Num(r.load_region["excess_ratio"].get<double>()) + " × noise²).</p>";
  }
  return h;
}

/// Plots of the channel with most residual energy: against time, before/after, against load; the
/// residual spectrum.
std::string HtmlPlots(const DiagData& data, const Report& r) {
  const Context& cx = r.cx;
  std::string h;
  int c = 0;
  double be = -1;
  const std::vector<int> pick =
      r.mismatch_channels.empty() ? std::vector<int>{} : r.mismatch_channels;
  for (int k = 0; k < cx.nc; ++k) {
    const double e = cx.resid.col(k).cast<double>().squaredNorm() * cx.weight(k);
    if (e > be) {
      be = e;
      c = k;
    }
  }
  PlotSeries res{data.t_s, {}, "#888", "residual b" + std::to_string(c)};
  PlotSeries model{data.t_s, {}, "#d22", "model"};
  PlotSeries after{data.t_s, {}, "#26c", "after"};
  res.y.resize(data.rows());
  model.y.resize(data.rows());
  after.y.resize(data.rows());
  for (std::size_t i = 0; i < data.rows(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    res.y[i] = cx.resid(ii, c);
    model.y[i] = r.model(ii, c);
    after.y[i] = static_cast<double>(cx.resid(ii, c)) - r.model(ii, c);
  }
  PlotSpec p1;
  p1.title = "Residual real − sim of b" + std::to_string(c) +
             " against time (shaded: located mismatch windows)";
  p1.x_label = "t (s)";
  p1.y_label = "mV/V";
  p1.spans = r.windows;
  for (const Transition& t : cx.conditioning.transitions) {
    if (t.excluded) p1.excluded.emplace_back(t.excluded_from_s, t.excluded_to_s);
  }
  for (const Glitch& g : cx.conditioning.glitches) p1.marks.push_back(g.t_s);
  h += "<h2>Residual against time</h2>";
  if (!p1.excluded.empty() || !p1.marks.empty()) {
    h += "<p>Blue bands: load transitions kept out of the fits; red lines: converter glitches.</p>";
  }
  h += SvgPlot(p1, {res, model});
  PlotSpec p2 = p1;
  p2.title = "Before (grey) and after removing the model (blue), b" + std::to_string(c);
  p2.spans.clear();
  h += SvgPlot(p2, {res, after});
  if (data.has_wrench()) {
    int k = 2;
    if (!r.load_region.is_null() && r.load_region.contains("range")) {
      const std::string comp = r.load_region["component"].get<std::string>();
      for (int j = 0; j < 6; ++j) {
        if (comp == kWrenchAxisNames[j]) k = j;
      }
    }
    PlotSeries sc{{}, res.y, "#888", "residual", true};
    PlotSeries sm{{}, model.y, "#d22", "model", true};
    sc.x.resize(data.rows());
    for (std::size_t i = 0; i < data.rows(); ++i)
      sc.x[i] = data.wrench(static_cast<Eigen::Index>(i), k);
    sm.x = sc.x;
    PlotSpec p3;
    p3.title = std::string("Residual of b") + std::to_string(c) + " against " + kWrenchAxisNames[k];
    p3.x_label = std::string(kWrenchAxisNames[k]) + (k < 3 ? " (N)" : " (N·m)");
    p3.y_label = "mV/V";
    h += "<h2>Residual against load</h2>" + SvgPlot(p3, {sc, sm});
  }
  if (!r.spectrum_hz.empty()) {
    PlotSeries sp{std::vector<double>(r.spectrum_hz.begin() + 1, r.spectrum_hz.end()),
                  std::vector<double>(r.spectrum_power.begin() + 1, r.spectrum_power.end()), "#333",
                  "residual PSD / noise"};
    PlotSpec p4;
    p4.title = "Residual spectrum (Welch), averaged over channels, noise floor = 1";
    p4.x_label = "frequency (Hz)";
    p4.y_label = "power / noise";
    p4.log_y = true;
    h += "<h2>Spectrum</h2>" + SvgPlot(p4, {sp});
  }
  return h;
}

/// Every single effect tried, in held-out ranking order.
/// Data conditioning: the quiet noise per channel and where it was measured, the load
/// transitions kept out of the fits, the converter's wrong codes.
std::string HtmlConditioning(const DiagData& data, const Report& r) {
  const Conditioning& k = r.cx.conditioning;
  std::string h =
      "<h2>Data conditioning</h2><table><tr><th>channel</th><th>quiet noise "
      "(mV/V)</th><th>in " +
      HtmlEscape(data.real_unit_symbol) + "</th><th>measured in</th></tr>";
  for (std::size_t c = 0; c < k.noise.size(); ++c) {
    const QuietNoise& q = k.noise[c];
    const bool have = q.holds > 0;
    h += "<tr><td>b" + std::to_string(c) + "</td><td>" + (have ? Num(q.sigma_mvv) : "—") +
         "</td><td>" +
         (have && data.real_units_per_mvv > 0 ? Num(q.sigma_mvv * data.real_units_per_mvv) : "—") +
         "</td><td>" +
         (have ? "hold " + Num(q.from_s) + "–" + Num(q.to_s) + " s (quietest of " +
                     std::to_string(q.holds) + " holds)"
               : "no hold long enough") +
         "</td></tr>";
  }
  h += "</table><p>Quiet noise: robust σ of first differences inside holds of the reference.</p>";
  std::size_t lagging = 0;
  double app_max = 0.0;
  for (const Transition& t : k.transitions) {
    lagging += t.excluded ? 1 : 0;
    if (t.excluded) app_max = std::max(app_max, t.application_s);
  }
  const Quantisation& q = r.cx.quantisation;
  if (q.quantised()) {
    int gridded = 0;
    for (Eigen::Index c = 0; c < q.step_mvv.size(); ++c) gridded += q.step_mvv(c) > 0 ? 1 : 0;
    h += "<p><b>Quantised record</b> (grid " + HtmlEscape(q.source) + "): steps of " +
         StepRange(q.step_mvv, 1.0) + " mV/V" +
         (gridded < q.step_mvv.size() ? " on " + std::to_string(gridded) + " of " +
                                            std::to_string(q.step_mvv.size()) + " bridges"
                                      : std::string()) +
         ". An effect smaller than " + Num(kResolvableSteps, "%.0f") + " steps (RMS " +
         StepRange(q.step_mvv, kResolvableSteps) +
         " mV/V) is not claimed: the grid's rounding could mimic it.</p>";
  }
  h += "<p>Load transitions measured: " + std::to_string(k.transitions.size()) + "; " +
       std::to_string(lagging) + " lag the reference" +
       (lagging > 0 ? " (real load applied over up to " + Num(app_max, "%.2g") +
                          " s): their rows are <b>excluded</b> from every fit and hold-out score"
                    : std::string()) +
       ". Rows excluded with the glitches: " + std::to_string(k.excluded_rows) + ".</p>";
  if (!k.glitches.empty()) {
    h += "<h2>" + HtmlEscape(std::string(EffectOf(EffectKind::kConverterGlitch).name)) +
         "</h2><p>" + std::to_string(k.glitches.size()) +
         " isolated wrong codes, each kept out of every fit:</p><table><tr><th>t (s)</th>"
         "<th>channel</th><th>offset (mV/V)</th></tr>";
    for (const Glitch& g : k.glitches) {
      h += "<tr><td>" + Num(g.t_s) + "</td><td>b" + std::to_string(g.channel) + "</td><td>" +
           Num(g.offset_mvv) + "</td></tr>";
    }
    h += "</table>";
  }
  return h;
}

std::string HtmlCandidates(const Report& r) {
  std::string h;
  h += "<h2>All candidates (held-out "
       "ranking)</h2><table><tr><th>effect</th><th>model</th><th>params</th>"
       "<th>held-out RMS after</th><th>z</th><th>score</th><th>claimable</th></tr>";
  for (const auto& cand : r.candidates) {
    h += "<tr><td>" + HtmlEscape(cand.name) + "</td><td>" + HtmlEscape(cand.variant) + "</td><td>" +
         std::to_string(cand.n_params) + "</td><td>" + Num(cand.hold_rms_after) + "</td><td>" +
         Num(cand.z, "%.1f") + "</td><td>" + Num(cand.score, "%.1f") + "</td><td>" +
         (cand.eligible ? "yes" : "") +
         (cand.not_resolved.empty() ? "" : "not resolved: " + HtmlEscape(cand.not_resolved)) +
         "</td></tr>";
  }
  h += "</table><p>Held-out rows: every third block of " + Num(r.cx.block_s) +
       " s. Score = held-out Δχ² − parameters × ln(held-out samples); an effect is claimed when "
       "its held-out z &gt; 6 and score &gt; 0 and its fit is resolved (no parameter on a search "
       "bound or outside its physical range; on a quantised record, a prediction of more than " +
       Num(kResolvableSteps, "%.0f") + " grid steps RMS).</p>";
  return h;
}

std::string HtmlReport(const DiagData& data, const Report& r) {
  std::string h;
  h += "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>ftdiag report</title><style>"
       "body{font-family:sans-serif;margin:20px;max-width:1060px}table{border-collapse:collapse}"
       "td,th{border:1px solid #bbb;padding:3px 8px;font-size:13px}th{background:#eee}"
       "code{word-break:break-all}.verdict{font-size:22px;font-weight:bold}.ev{background:#eef6ee;"
       "padding:6px;border-left:"
       "4px solid #4a4}.conf{background:#fbeeee;padding:6px;border-left:4px solid #c44}"
       "</style></head><body>";
  h += "<h1>ftdiag: sim vs real</h1>";
  h += "<p>Real: <code>" + HtmlEscape(data.real_name) + "</code>, sim: <code>" +
       HtmlEscape(data.sim_name) + "</code>, " + std::to_string(data.rows()) + " rows × " +
       std::to_string(data.channels()) + " bridges at " + Num(r.rate_hz) + " Hz.</p>";
  if (data.segment.size() == data.rows() && r.cx.segments > 1) {
    h += "<p>" + std::to_string(r.cx.segments) +
         " joined recordings (segments): stateful models restart at each, hold-out blocks never "
         "straddle one.</p>";
  }
  h += "<p class=\"verdict\">Verdict: " + HtmlEscape(r.verdict);
  for (std::size_t i = 1; i < r.effects.size(); ++i) h += " + " + HtmlEscape(r.effects[i].fit.name);
  h += "</p>";
  h += "<p>Held-out RMS (rows not used for fitting, all channels): <b>" + Num(r.hold_rms_before) +
       "</b> → <b>" + Num(r.hold_rms_after) + "</b> mV/V.</p>";
  for (const auto& e : r.effects) {
    h += "<h2>" + HtmlEscape(e.fit.name) + "</h2><p class=\"ev\">" + HtmlEscape(e.fit.evidence) +
         "</p><p>Model: " + HtmlEscape(e.fit.variant) + " (" + std::to_string(e.fit.n_params) +
         " parameters). Held-out RMS " + Num(e.hold_rms_before) + " → " + Num(e.hold_rms_after) +
         " mV/V.</p>" + ParamTable(e.fit, TypedParameters(r.cx, e.fit)) + StandardTable(e.fit);
    if (!e.confounded_with.empty()) {
      h += "<p class=\"conf\"><b>Not identified.</b> " + HtmlEscape(e.confounding) +
           " The verdict does not name it.</p>";
    }
  }
  // Partners of a pair left unclaimed (JSON "not_claimed": "name: reason"), in words.
  for (const auto& d : r.dropped) {
    const std::size_t colon = d.find(": ");
    const std::string name = colon == std::string::npos ? d : d.substr(0, colon);
    const std::string why = colon == std::string::npos ? "" : d.substr(colon + 2);
    h += "<h2>" + HtmlEscape(name) + " (not claimed)</h2><p class=\"conf\"><b>Not claimed.</b> " +
         HtmlEscape(name) +
         " improved the held-out rows, but it is left out of the effects and the verdict: " +
         HtmlEscape(why) + "</p>";
  }
  h += HtmlChannels(r);
  h += HtmlConditioning(data, r);
  h += HtmlPlots(data, r);
  h += HtmlCandidates(r);
  h += "</body></html>\n";
  return h;
}

void WriteHtml(const std::string& path, const DiagData& data, const Report& report) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << HtmlReport(data, report);
  if (!out) throw std::runtime_error(path + ": write failed");
}

void WriteJson(const std::string& path, const nlohmann::json& j) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string SummaryText(const Report& report) {
  char buf[160];
  std::string s = "verdict: " + report.verdict;
  // The verdict is the first identified claim: the claims are listed apart when it is not the
  // first (an unidentified claim ranks above it, or none is identified).
  const bool verdict_first =
      !report.effects.empty() && report.effects[0].fit.name == report.verdict;
  std::string claims;
  for (std::size_t i = verdict_first ? 1 : 0; i < report.effects.size(); ++i) {
    const ClaimedEffect& e = report.effects[i];
    claims += (verdict_first || i > 0 ? " + " : "") + e.fit.name;
    if (!verdict_first && !e.confounded_with.empty()) claims += " (not identified)";
  }
  s += verdict_first || claims.empty() ? claims : "; claimed: " + claims;
  std::snprintf(buf, sizeof buf, "  (held-out RMS %.4g -> %.4g mV/V)\n", report.hold_rms_before,
                report.hold_rms_after);
  s += buf;
  for (const auto& e : report.effects) {
    s += "  " + e.fit.name + ": " + e.fit.evidence + "\n";
    if (!e.confounded_with.empty()) s += "    not identified: " + e.confounding + "\n";
  }
  return s;
}

}  // namespace ftstack::diag
