// Presenting a fit: calibration file from a fit result, terminal summary, self-contained HTML
// report.
#pragma once

#include <string>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/fit.hpp"

namespace ftstack::cal {

/// The calibration file for a fit: matrix, terms, ADC, rated ranges, uncertainty (held-out RMS)
/// and a "fit" section (model, λ, the choice's margins and their standard errors, folds, blocks,
/// held-out RMS/95 %, parameter uncertainty, condition numbers). Throws CalFileError if the
/// fixed-point loader refuses it.
[[nodiscard]] CalFile CalFileFromFit(const FitResult& fit, const hal::AdcInfo& adc,
                                     const std::string& serial, const std::string& date);

/// The model choice in one or two lines: the chosen candidate, its margin over the simplest and
/// that margin's standard error, and the more complex candidate closest to being taken.
[[nodiscard]] std::string ChoiceLine(const FitResult& fit);

/// Multi-line terminal summary: model choice, per-axis held-out RMS and 95 % error in % of rated,
/// uncertainty, condition numbers, worst-case fixed-point error, worst blocks.
[[nodiscard]] std::string FitSummary(const FitResult& fit, const fw::LoadReport& fixed);

/// Writes a self-contained HTML report (inline SVG plots, no network): summary tables, held-out
/// error bars, residuals against each wrench component, candidates and worst blocks.
void WriteFitReport(const std::string& path, const FitResult& fit, const RigData& data,
                    const fw::LoadReport& fixed, const std::string& title);

}  // namespace ftstack::cal
