#include "sim/design/catalog.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "sim/design/catalog_csv.hpp"

namespace ftstack::sim::design {
namespace {

struct Field {
  std::string text;
  int column = 1;
};

std::vector<Field> SplitCsv(const std::string& line, const std::string& where) {
  std::vector<Field> out;
  Field cur;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted) {
      if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cur.text += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        cur.text += ch;
      }
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == ',') {
      out.push_back(cur);
      cur = Field{"", static_cast<int>(i) + 2};
    } else if (ch != '\r') {
      cur.text += ch;
    }
  }
  if (quoted) throw std::runtime_error(where + ": unterminated quote");
  out.push_back(cur);
  return out;
}

/// A number with an optional trailing '?'; blank gives NaN.
double Value(const Field& f, const std::string& where, bool* confirmed) {
  std::string t = f.text;
  *confirmed = !t.empty() && t.back() != '?';
  if (!t.empty() && t.back() == '?') t.pop_back();
  if (t.empty()) return NAN;
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(t, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != t.size() || !std::isfinite(v) || v <= 0) {
    throw std::runtime_error(where + ":" + std::to_string(f.column) + ": '" + f.text +
                             "' is not a positive number");
  }
  return v;
}

}  // namespace

Catalog ParseCatalog(const std::string& text, const std::string& origin) {
  Catalog c;
  c.origin = origin;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string where = origin + ":" + std::to_string(n);
    if (n == 1) {
      if (line.rfind("vendor,model,calibration,Fxy_N,Fz_N,Txy_Nm,Tz_Nm,res_Fxy_N", 0) != 0) {
        throw std::runtime_error(where + ":1: unexpected header");
      }
      continue;
    }
    if (line.empty() || line == "\r") continue;
    const std::vector<Field> f = SplitCsv(line, where);
    if (f.size() != 14) {
      throw std::runtime_error(where + ":1: expected 14 fields, found " + std::to_string(f.size()));
    }
    CatalogRow r;
    r.line = n;
    r.vendor = f[0].text;
    r.model = f[1].text;
    r.calibration = f[2].text;
    r.source = f[13].text;
    bool ok = false;
    r.fxy_n = Value(f[3], where, &r.fxy_confirmed);
    r.fz_n = Value(f[4], where, &ok);
    r.txy_nm = Value(f[5], where, &r.txy_confirmed);
    r.tz_nm = Value(f[6], where, &ok);
    r.res_fxy_n = Value(f[7], where, &r.res_confirmed);
    c.rows.push_back(r);
  }
  return c;
}

Catalog LoadCatalog(const std::string& path) {
  if (path.empty()) return ParseCatalog(kCatalogCsv, "sim/design/data/ft_catalog.csv");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseCatalog(ss.str(), path);
}

Trend FitTrend(const Catalog& c, bool confirmed_only) {
  Trend t;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const CatalogRow& r : c.rows) {
    if (std::isnan(r.fxy_n) || std::isnan(r.txy_nm)) continue;
    if (confirmed_only && !(r.fxy_confirmed && r.txy_confirmed)) continue;
    const double x = std::log(r.fxy_n), y = std::log(r.txy_nm);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
    t.used.push_back(&r);
  }
  t.n = static_cast<int>(t.used.size());
  const double den = t.n * sxx - sx * sx;
  if (t.n < 2 || !(den > 1e-12)) throw std::runtime_error(c.origin + ": too few rows for a trend");
  t.exponent = (t.n * sxy - sx * sy) / den;
  t.coefficient = std::exp((sy - t.exponent * sx) / t.n);
  return t;
}

}  // namespace ftstack::sim::design
