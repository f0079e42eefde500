// The commercial F/T sensor survey (sim/design/data/ft_catalog.csv) and its power-law trend.
#pragma once

#include <string>
#include <vector>

namespace ftstack::sim::design {

/// One catalogue row; a value the survey marks with a trailing '?' is unconfirmed; NaN = blank.
struct CatalogRow {
  std::string vendor, model, calibration, source;
  double fxy_n = 0, fz_n = 0, txy_nm = 0, tz_nm = 0, res_fxy_n = 0;
  bool fxy_confirmed = false, txy_confirmed = false, res_confirmed = false;
  int line = 0;  ///< line in the CSV file
};

struct Catalog {
  std::string origin;
  std::vector<CatalogRow> rows;
};

/// Parses the survey CSV (header vendor,model,calibration,Fxy_N,Fz_N,Txy_Nm,Tz_Nm,res_Fxy_N,…,
/// source). Throws std::runtime_error naming origin:line:column on a malformed row.
[[nodiscard]] Catalog ParseCatalog(const std::string& text, const std::string& origin);
/// Reads a CSV file; an empty path gives the compiled-in copy of sim/design/data/ft_catalog.csv.
[[nodiscard]] Catalog LoadCatalog(const std::string& path);

/// Least-squares line in log space: ln Txy = ln coefficient + exponent · ln Fxy.
struct Trend {
  double coefficient = 0, exponent = 0;
  int n = 0;
  std::vector<const CatalogRow*> used;
};
/// Fit over the rows whose Fxy and Txy are both confirmed (all rows with values if
/// `confirmed_only` is false). Throws std::runtime_error with fewer than 2 distinct rows.
[[nodiscard]] Trend FitTrend(const Catalog& c, bool confirmed_only);

}  // namespace ftstack::sim::design
