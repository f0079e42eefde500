#include "calibration/fit/ati.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

namespace ftstack::cal {
namespace {

/// One XML start (or empty) element with its attributes and position.
struct Element {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::size_t line = 1;
  std::size_t column = 1;
};

class Scanner {
 public:
  Scanner(const std::string& text, std::string path) : text_(text), path_(std::move(path)) {}

  /// 1-based line and column of byte `pos`.
  void Position(std::size_t pos, std::size_t* line, std::size_t* col) const {
    *line = 1;
    *col = 1;
    for (std::size_t i = 0; i < pos && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++*line;
        *col = 1;
      } else {
        ++*col;
      }
    }
  }

  [[noreturn]] void Fail(std::size_t pos, const std::string& why) const {
    std::size_t line = 1;
    std::size_t col = 1;
    Position(pos, &line, &col);
    throw CalFileError(path_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + why);
  }

  /// All elements in document order; checks that tags close and the root element ends.
  std::vector<Element> Elements() {
    std::vector<Element> out;
    std::vector<std::string> open;
    std::size_t i = 0;
    while ((i = text_.find('<', i)) != std::string::npos) {
      const std::size_t start = i;
      if (text_.compare(i, 4, "<!--") == 0) {
        const std::size_t e = text_.find("-->", i + 4);
        if (e == std::string::npos) Fail(start, "unterminated comment (truncated file?)");
        i = e + 3;
        continue;
      }
      if (text_.compare(i, 2, "<?") == 0) {
        const std::size_t e = text_.find("?>", i + 2);
        if (e == std::string::npos) Fail(start, "unterminated declaration (truncated file?)");
        i = e + 2;
        continue;
      }
      const std::size_t end = FindTagEnd(i);
      if (text_[i + 1] == '/') {
        const std::string name = Trim(text_.substr(i + 2, end - i - 2));
        if (open.empty() || open.back() != name) Fail(start, "unexpected </" + name + ">");
        open.pop_back();
        i = end + 1;
        continue;
      }
      Element el = ParseTag(i, end);
      const bool empty = text_[end - 1] == '/';
      if (!empty) open.push_back(el.name);
      out.push_back(std::move(el));
      i = end + 1;
    }
    if (out.empty()) Fail(0, "no XML elements: not an ATI calibration file");
    if (!open.empty()) Fail(text_.size(), "<" + open.back() + "> is not closed (truncated file?)");
    return out;
  }

 private:
  std::size_t FindTagEnd(std::size_t i) const {
    bool quoted = false;
    for (std::size_t k = i + 1; k < text_.size(); ++k) {
      if (text_[k] == '"') quoted = !quoted;
      if (!quoted && text_[k] == '>') return k;
      if (!quoted && text_[k] == '<') Fail(k, "'<' inside a tag");
    }
    Fail(i, "unterminated tag (truncated file?)");
  }

  static std::string Trim(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t\r\n");
    const std::size_t b = s.find_last_not_of(" \t\r\n");
    return a == std::string::npos ? "" : s.substr(a, b - a + 1);
  }

  Element ParseTag(std::size_t lt, std::size_t gt) const {
    Element el;
    std::size_t line = 1;
    std::size_t col = 1;
    Position(lt, &line, &col);
    el.line = line;
    el.column = col;
    std::size_t k = lt + 1;
    while (k < gt && !std::isspace(static_cast<unsigned char>(text_[k])) && text_[k] != '/') {
      el.name += text_[k++];
    }
    if (el.name.empty()) Fail(lt, "element without a name");
    for (;;) {
      while (k < gt && (std::isspace(static_cast<unsigned char>(text_[k])) || text_[k] == '/')) ++k;
      if (k >= gt) break;
      const std::size_t name_start = k;
      while (k < gt && text_[k] != '=' && !std::isspace(static_cast<unsigned char>(text_[k]))) ++k;
      const std::string name = text_.substr(name_start, k - name_start);
      while (k < gt && std::isspace(static_cast<unsigned char>(text_[k]))) ++k;
      if (k >= gt || text_[k] != '=') Fail(name_start, "attribute '" + name + "' has no value");
      ++k;
      while (k < gt && std::isspace(static_cast<unsigned char>(text_[k]))) ++k;
      if (k >= gt || text_[k] != '"') Fail(k, "attribute '" + name + "' value is not quoted");
      const std::size_t close = text_.find('"', k + 1);
      // A quote swallowed by a malformed attribute name leaves this value open up to the tag's end
      // (found by fuzzing: the scan then restarted at 0 and never ended).
      if (close == std::string::npos || close >= gt)
        Fail(k, "attribute '" + name + "' value is not closed");
      el.attrs[name] = text_.substr(k + 1, close - k - 1);
      k = close + 1;
    }
    return el;
  }

  const std::string& text_;
  std::string path_;
};

std::string Where(const std::string& path, const Element& e) {
  return path + ":" + std::to_string(e.line) + ":" + std::to_string(e.column);
}

const std::string& Attr(const std::string& path, const Element& e, const std::string& name) {
  const auto it = e.attrs.find(name);
  if (it == e.attrs.end()) {
    throw CalFileError(Where(path, e) + ": <" + e.name + "> has no " + name + " attribute");
  }
  return it->second;
}

double Number(const std::string& path, const Element& e, const std::string& what,
              const std::string& text) {
  const char* s = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  while (end != nullptr && std::isspace(static_cast<unsigned char>(*end))) ++end;
  if (end == s || (end != nullptr && *end != '\0') || errno == ERANGE || !std::isfinite(v)) {
    throw CalFileError(Where(path, e) + ": " + what + " '" + text + "' is not a finite number");
  }
  return v;
}

std::vector<double> Numbers(const std::string& path, const Element& e, const std::string& what,
                            const std::string& text) {
  std::vector<double> out;
  std::istringstream ss(text);
  std::string tok;
  while (ss >> tok) out.push_back(Number(path, e, what, tok));
  return out;
}

int AxisIndex(const std::string& name) {
  static const char* const kNames[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  for (int i = 0; i < 6; ++i) {
    if (name == kNames[i]) return i;
  }
  return -1;
}

}  // namespace

double AtiForceToN(const std::string& u) {
  constexpr double kLbf = 4.4482216152605;
  if (u == "lb" || u == "lbf") return kLbf;
  if (u == "klb" || u == "klbf") return 1000.0 * kLbf;
  if (u == "N") return 1.0;
  if (u == "kN") return 1000.0;
  if (u == "kg" || u == "kgf") return 9.80665;
  if (u == "g" || u == "gf") return 9.80665e-3;
  return 0.0;
}

double AtiTorqueToNm(const std::string& u) {
  constexpr double kLbfIn = 4.4482216152605 * 0.0254;
  if (u == "in-lb" || u == "in-lbf" || u == "lb-in" || u == "lbf-in") return kLbfIn;
  if (u == "ft-lb" || u == "lb-ft" || u == "ft-lbf" || u == "lbf-ft") return 12.0 * kLbfIn;
  if (u == "N-m" || u == "Nm") return 1.0;
  if (u == "N-mm" || u == "Nmm") return 1e-3;
  if (u == "kg-cm" || u == "kgcm") return 9.80665e-2;
  if (u == "kN-m" || u == "kNm") return 1000.0;
  return 0.0;
}

double AtiDistanceToM(const std::string& u) {
  if (u == "in") return 0.0254;
  if (u == "m") return 1.0;
  if (u == "cm") return 0.01;
  if (u == "mm") return 0.001;
  if (u == "ft") return 0.3048;
  return 0.0;
}

double AtiAngleToDeg(const std::string& u) {
  if (u == "deg" || u == "degrees" || u == "degree") return 1.0;
  if (u == "rad" || u == "radians" || u == "radian") return 180.0 / std::numbers::pi;
  return 0.0;
}

Eigen::Matrix<double, 6, 6> AtiWrenchTransform(const Eigen::Vector3d& d, double rx_deg,
                                               double ry_deg, double rz_deg) {
  const double k = std::numbers::pi / 180.0;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(rx_deg * k, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(ry_deg * k, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rz_deg * k, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  Eigen::Matrix3d dx;  // dx·v = d × v
  dx << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
  Eigen::Matrix<double, 6, 6> t = Eigen::Matrix<double, 6, 6>::Zero();
  t.topLeftCorner<3, 3>() = r.transpose();
  t.bottomRightCorner<3, 3>() = r.transpose();
  t.bottomLeftCorner<3, 3>() = -r.transpose() * dx;
  return t;
}

namespace {

/// The elements of an ATI .cal file the import reads, found in one pass.
struct AtiElements {
  const Element* sensor = nullptr;
  const Element* calib = nullptr;
  const Element* basic = nullptr;
  std::vector<const Element*> axes;
  std::vector<const Element*> user_axes;
  std::vector<std::string> ignored;
};

AtiElements FindElements(const std::vector<Element>& els) {
  AtiElements found;
  for (const Element& e : els) {
    if (e.name == "FTSensor" && found.sensor == nullptr) {
      found.sensor = &e;
    } else if (e.name == "Calibration") {
      if (found.calib != nullptr) {
        found.ignored.push_back("only the first <Calibration> is imported");
        break;
      }
      found.calib = &e;
    } else if (e.name == "Axis") {
      found.axes.push_back(&e);
    } else if (e.name == "UserAxis") {
      found.user_axes.push_back(&e);
    } else if (e.name == "BasicTransform") {
      found.basic = &e;
    } else if (e.name == "BiasSlope" || e.name == "GainSlope" || e.name == "Thermistor") {
      found.ignored.push_back("ATI software temperature compensation (" + e.name +
                              ") is not imported: it works on a thermistor voltage, not °C");
    }
  }
  return found;
}

/// What reading a block of axis rows needs: the file, its <Calibration>, the gauge count and the
/// SI factors of the force and torque units.
struct RowContext {
  const std::string& path;
  const Element& calib;
  int n = 0;
  double f_si = 0;
  double t_si = 0;
};

/// Reads six named rows (values ÷ scale if `scaled`, the scales into `axis_scale`), SI units; rated
/// max per axis.
void ReadRows(const RowContext& ctx, const std::vector<const Element*>& rows, bool scaled,
              Eigen::MatrixXd* m, std::array<double, 6>* rated, std::array<double, 6>* axis_scale) {
  const std::string& path = ctx.path;
  const int n = ctx.n;
  m->setZero(6, n);
  std::array<bool, 6> seen{};
  for (const Element* e : rows) {
    const int a = AxisIndex(Attr(path, *e, "Name"));
    if (a < 0) {
      throw CalFileError(Where(path, *e) + ": axis name '" + e->attrs.at("Name") +
                         "' is not Fx, Fy, Fz, Tx, Ty or Tz");
    }
    if (seen[static_cast<std::size_t>(a)]) {
      throw CalFileError(Where(path, *e) + ": axis " + e->attrs.at("Name") + " given twice");
    }
    seen[static_cast<std::size_t>(a)] = true;
    const std::vector<double> vals = Numbers(path, *e, "value", Attr(path, *e, "values"));
    if (static_cast<int>(vals.size()) != n) {
      throw CalFileError(Where(path, *e) + ": " + std::to_string(vals.size()) +
                         " values, NumGages says " + std::to_string(n));
    }
    double scale = 1.0;
    if (scaled && e->attrs.count("scale") != 0) {
      scale = Number(path, *e, "scale", e->attrs.at("scale"));
      if (scale == 0) throw CalFileError(Where(path, *e) + ": scale is zero");
    }
    if (scaled) (*axis_scale)[static_cast<std::size_t>(a)] = scale;
    const double unit = a < 3 ? ctx.f_si : ctx.t_si;
    for (int c = 0; c < n; ++c) (*m)(a, c) = vals[static_cast<std::size_t>(c)] / scale * unit;
    if (e->attrs.count("max") != 0) {
      (*rated)[static_cast<std::size_t>(a)] =
          std::fabs(Number(path, *e, "max", e->attrs.at("max"))) * unit;
    }
  }
  for (int a = 0; a < 6; ++a) {
    if (!seen[static_cast<std::size_t>(a)]) {
      throw CalFileError(Where(path, ctx.calib) + ": axis " + std::string(a < 3 ? "F" : "T") +
                         "xyz"[a % 3] + " is missing");
    }
  }
}

/// The <BasicTransform> as a wrench transform (identity when the file has none).
Eigen::Matrix<double, 6, 6> ReadBasicTransform(const std::string& path, const Element& calib,
                                               const Element* basic) {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  double r[3] = {0, 0, 0};
  if (basic != nullptr) {
    const std::string du = Attr(path, calib, "DistUnits");
    const double d_si = AtiDistanceToM(du);
    if (d_si == 0) throw CalFileError(Where(path, calib) + ": unknown DistUnits '" + du + "'");
    const auto au = calib.attrs.find("AngleUnits");
    const double a_deg = AtiAngleToDeg(au != calib.attrs.end() ? au->second : "degrees");
    if (a_deg == 0) throw CalFileError(Where(path, calib) + ": unknown AngleUnits");
    const char* dn[3] = {"Dx", "Dy", "Dz"};
    const char* rn[3] = {"Rx", "Ry", "Rz"};
    for (int i = 0; i < 3; ++i) {
      if (basic->attrs.count(dn[i]) != 0) {
        d(i) = Number(path, *basic, dn[i], basic->attrs.at(dn[i])) * d_si;
      }
      if (basic->attrs.count(rn[i]) != 0) {
        r[i] = Number(path, *basic, rn[i], basic->attrs.at(rn[i])) * a_deg;
      }
    }
  }
  return AtiWrenchTransform(d, r[0], r[1], r[2]);
}

/// Warns for each row where the Axis and UserAxis matrices disagree beyond their print rounding.
void CompareAxisWithUserAxis(const RowContext& ctx, const std::array<double, 6>& axis_scale,
                             const Eigen::Matrix<double, 6, 6>& transform, AtiImport* imp) {
  // Both kinds of rows are printed with 5 decimals in file units: the Axis values' rounding
  // (÷ scale, through the transform) plus the UserAxis rounding bound the honest difference.
  static const char* const kNames[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  Eigen::Matrix<double, 6, 1> axis_round;
  for (int a = 0; a < 6; ++a) {
    axis_round(a) =
        0.5e-5 / std::fabs(axis_scale[static_cast<std::size_t>(a)]) * (a < 3 ? ctx.f_si : ctx.t_si);
  }
  const Eigen::Matrix<double, 6, 1> propagated = transform.cwiseAbs() * axis_round;
  for (int a = 0; a < 6; ++a) {
    const double unit = a < 3 ? ctx.f_si : ctx.t_si;
    const double tol = (0.5e-5 * unit + propagated(a)) * 1.01 +
                       1e-9 * imp->from_user_axis.row(a).cwiseAbs().maxCoeff();
    const double diff = (imp->from_axis.row(a) - imp->from_user_axis.row(a)).cwiseAbs().maxCoeff();
    if (diff > tol) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "%s row: Axis/scale with BasicTransform and UserAxis disagree by %.3g %s/V "
                    "(rounding allows %.3g); using UserAxis",
                    kNames[a], diff, a < 3 ? "N" : "N*m", tol);
      imp->warnings.push_back(buf);
    }
  }
}

/// The DAQ's input range: OutputRange volts span, bipolar by default; 16-bit converter.
void FillAdcRange(const std::string& path, const Element& calib, int n, CalFile* f) {
  double range_v = 20.0;
  const auto orange = calib.attrs.find("OutputRange");
  if (orange != calib.attrs.end()) range_v = Number(path, calib, "OutputRange", orange->second);
  const auto bip = calib.attrs.find("OutputBipolar");
  const bool bipolar = bip == calib.attrs.end() || bip->second != "False";
  const double full_scale_v = bipolar ? range_v / 2.0 : range_v;
  if (!(full_scale_v > 0))
    throw CalFileError(Where(path, calib) + ": OutputRange must be positive");
  f->adc.channel_count = static_cast<std::uint8_t>(n);
  f->adc.max_counts = 32767;
  f->adc.min_counts = -32768;
  f->adc.full_scale_nvv = std::llround(full_scale_v * 1e6);  // input unit × 1e-6 (µV)
}

}  // namespace

AtiImport ParseAtiCal(const std::string& text, const std::string& path) {
  Scanner scan(text, path);
  const std::vector<Element> els = scan.Elements();
  const AtiElements found = FindElements(els);
  const Element* sensor = found.sensor;
  const Element* calib = found.calib;
  if (sensor == nullptr)
    throw CalFileError(path + ":1:1: no <FTSensor> element: not an ATI .cal file");
  if (calib == nullptr) throw CalFileError(Where(path, *sensor) + ": no <Calibration> element");
  const std::string& gages = Attr(path, *sensor, "NumGages");
  const double n_gages = Number(path, *sensor, "NumGages", gages);
  // Range first: a number beyond int (found by fuzzing) must not reach the conversion.
  if (!(n_gages >= 1.0 && n_gages < static_cast<double>(fw::kMaxChannels) + 1.0)) {
    throw CalFileError(Where(path, *sensor) + ": NumGages " + gages + " outside 1..8");
  }
  const int n = static_cast<int>(n_gages);
  AtiImport imp;
  const auto v = sensor->attrs.find("CalFileVersion");
  imp.version = v != sensor->attrs.end() ? v->second : "1.0";
  const std::string& fu = Attr(path, *calib, "ForceUnits");
  const std::string& tu = Attr(path, *calib, "TorqueUnits");
  const RowContext ctx{path, *calib, n, AtiForceToN(fu), AtiTorqueToNm(tu)};
  if (ctx.f_si == 0) throw CalFileError(Where(path, *calib) + ": unknown ForceUnits '" + fu + "'");
  if (ctx.t_si == 0) throw CalFileError(Where(path, *calib) + ": unknown TorqueUnits '" + tu + "'");

  std::array<double, 6> axis_scale{};
  std::array<double, 6> rated{};
  Eigen::Matrix<double, 6, 6> transform = Eigen::Matrix<double, 6, 6>::Identity();
  if (!found.axes.empty()) {
    Eigen::MatrixXd basic_m;
    ReadRows(ctx, found.axes, true, &basic_m, &rated, &axis_scale);
    transform = ReadBasicTransform(path, *calib, found.basic);
    imp.from_axis = transform * basic_m;
  }
  if (!found.user_axes.empty()) {
    std::array<double, 6> user_rated{};
    ReadRows(ctx, found.user_axes, false, &imp.from_user_axis, &user_rated, &axis_scale);
    for (std::size_t a = 0; a < 6; ++a) {
      if (user_rated[a] > 0) rated[a] = user_rated[a];
    }
  }
  if (found.axes.empty() && found.user_axes.empty()) {
    throw CalFileError(Where(path, *calib) + ": no <Axis> or <UserAxis> rows");
  }
  imp.used_user_axis = !found.user_axes.empty();
  const Eigen::MatrixXd& m = imp.used_user_axis ? imp.from_user_axis : imp.from_axis;
  if (!found.axes.empty() && !found.user_axes.empty()) {
    CompareAxisWithUserAxis(ctx, axis_scale, transform, &imp);
  }
  for (const std::string& s : found.ignored) imp.warnings.push_back(s);

  CalFile& f = imp.file;
  f.source = "ati";
  f.input_unit = "V";
  const auto serial = sensor->attrs.find("Serial");
  if (serial != sensor->attrs.end()) f.serial = serial->second;
  const auto date = calib->attrs.find("CalDate");
  if (date != calib->attrs.end()) f.date = date->second;
  f.cal.channel_count = static_cast<std::uint8_t>(n);
  for (int a = 0; a < 6; ++a) {
    for (int c = 0; c < n; ++c) {
      f.cal.matrix[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)] = m(a, c);
    }
  }
  f.rated = rated;
  FillAdcRange(path, *calib, n, &f);
  f.extra["ati"] = {
      {"version", imp.version},
      {"matrix_from", imp.used_user_axis ? "UserAxis" : "Axis/scale + BasicTransform"},
      {"force_units", fu},
      {"torque_units", tu},
      {"warnings", imp.warnings}};
  return imp;
}

AtiImport ImportAtiCal(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CalFileError(path + ": cannot open: " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseAtiCal(ss.str(), path);
}

}  // namespace ftstack::cal
