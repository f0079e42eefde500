// The self-contained HTML report of a diagnosis: summary, evidence and SVG plots (no network).
#pragma once

#include <string>
#include <vector>

#include "diagnosis/engine/diagnose.hpp"

namespace ftstack::diag {

/// One data series of a plot.
struct PlotSeries {
  std::vector<double> x;
  std::vector<double> y;
  std::string color;
  std::string label;
  bool points = false;  ///< scatter instead of a line
};

/// Options of one SVG plot.
struct PlotSpec {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<std::pair<double, double>> spans;  ///< shaded x ranges
  std::vector<std::pair<double, double>>
      excluded;               ///< x ranges kept out of the fits (hatched blue)
  std::vector<double> marks;  ///< x positions marked by a red line
  bool log_y = false;
  int width = 1000;
  int height = 300;
};

/// An SVG line/scatter plot of the series (long series are reduced to min/max per pixel column).
[[nodiscard]] std::string SvgPlot(const PlotSpec& spec, const std::vector<PlotSeries>& series);

/// The report as one HTML document.
[[nodiscard]] std::string HtmlReport(const DiagData& data, const Report& report);
/// Writes HtmlReport to `path`; throws std::runtime_error naming the file on failure.
void WriteHtml(const std::string& path, const DiagData& data, const Report& report);
/// Writes the JSON report (ToJson) to `path`; throws std::runtime_error naming the file on failure.
void WriteJson(const std::string& path, const nlohmann::json& j);
/// The verdict and each effect's evidence, one line each (what ftdiag prints).
[[nodiscard]] std::string SummaryText(const Report& report);

}  // namespace ftstack::diag
