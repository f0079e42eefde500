// Similarity registration of measured strip edge points onto a model centre line.
#include "sim/pivot/shape_registration.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace ftstack::sim::pivot {

double Similarity2::AngleRad() const {
  Eigen::Matrix2d r = rotation;
  if (reflected) r = r * Eigen::Vector2d(1.0, -1.0).asDiagonal();
  return std::atan2(r(1, 0), r(0, 0));
}

Similarity2 FitSimilarity(const std::vector<Eigen::Vector2d>& from,
                          const std::vector<Eigen::Vector2d>& to, bool allow_reflection,
                          const std::vector<double>& weights) {
  if (from.size() != to.size() || from.size() < 2 ||
      (!weights.empty() && weights.size() != from.size())) {
    throw std::invalid_argument("similarity fit needs two equally long point lists of size >= 2");
  }
  auto weight = [&weights](size_t k) { return weights.empty() ? 1.0 : weights[k]; };
  double n = 0.0;
  Eigen::Vector2d mx = Eigen::Vector2d::Zero(), my = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < from.size(); ++k) {
    if (!(weight(k) >= 0.0)) throw std::invalid_argument("similarity fit: negative weight");
    n += weight(k);
    mx += weight(k) * from[k];
    my += weight(k) * to[k];
  }
  if (!(n > 0.0)) throw std::invalid_argument("similarity fit: weights sum to zero");
  mx /= n;
  my /= n;
  double var_x = 0.0;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (size_t k = 0; k < from.size(); ++k) {
    const Eigen::Vector2d dx = from[k] - mx, dy = to[k] - my;
    var_x += weight(k) * dx.squaredNorm();
    cov += weight(k) * dy * dx.transpose();
  }
  var_x /= n;
  cov /= n;
  if (!(var_x > 0.0) || !std::isfinite(var_x)) {
    throw std::invalid_argument("similarity fit: source points coincide");
  }
  // In 2-D the SVD of Umeyama's method has a closed form. For a proper rotation by phi the
  // objective trace(R·covᵀ) is a·cos(phi) + b·sin(phi) with a = cov00 + cov11, b = cov10 − cov01,
  // maximal sqrt(a² + b²) at phi = atan2(b, a). A reflection R = rot(phi)·diag(1, −1) gives the
  // same with the second column of cov negated.
  const double a = cov(0, 0) + cov(1, 1), b = cov(1, 0) - cov(0, 1);
  const double ar = cov(0, 0) - cov(1, 1), br = cov(1, 0) + cov(0, 1);
  const double proper = std::hypot(a, b), mirror = std::hypot(ar, br);
  Similarity2 t;
  t.reflected = allow_reflection && mirror > proper;
  const double phi = t.reflected ? std::atan2(br, ar) : std::atan2(b, a);
  const double c = std::cos(phi), s = std::sin(phi);
  t.rotation << c, -s, s, c;
  if (t.reflected) t.rotation = t.rotation * Eigen::Vector2d(1.0, -1.0).asDiagonal();
  t.scale = (t.reflected ? mirror : proper) / var_x;
  t.translation = my - t.scale * (t.rotation * mx);
  return t;
}

namespace {

struct CurvePoint {
  Eigen::Vector2d p;
  double distance;
};

CurvePoint ClosestOnPolyline(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  CurvePoint best{poly.front(), std::numeric_limits<double>::infinity()};
  for (size_t k = 0; k + 1 < poly.size(); ++k) {
    const Eigen::Vector2d a = poly[k], ab = poly[k + 1] - poly[k];
    const double len2 = ab.squaredNorm();
    const double u = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const Eigen::Vector2d c = a + u * ab;
    const double d = (q - c).norm();
    if (d < best.distance) best = {c, d};
  }
  return best;
}

std::vector<double> CumulativeFractions(const std::vector<Eigen::Vector2d>& poly) {
  std::vector<double> s(poly.size(), 0.0);
  for (size_t k = 1; k < poly.size(); ++k) s[k] = s[k - 1] + (poly[k] - poly[k - 1]).norm();
  if (s.back() > 0.0) {
    for (double& v : s) v /= s.back();
  }
  return s;
}

Eigen::Vector2d PointAtFraction(const std::vector<Eigen::Vector2d>& poly,
                                const std::vector<double>& frac, double f) {
  const auto it = std::lower_bound(frac.begin(), frac.end(), f);
  if (it == frac.begin()) return poly.front();
  if (it == frac.end()) return poly.back();
  const size_t k = static_cast<size_t>(it - frac.begin());
  const double span = frac[k] - frac[k - 1];
  const double u = span > 0.0 ? (f - frac[k - 1]) / span : 0.0;
  return poly[k - 1] + u * (poly[k] - poly[k - 1]);
}

void CheckFinite(const std::vector<Eigen::Vector2d>& pts, const char* what) {
  for (size_t k = 0; k < pts.size(); ++k) {
    if (!pts[k].allFinite()) {
      throw std::invalid_argument(std::string(what) + " point " + std::to_string(k) +
                                  " is not finite");
    }
  }
}

// Alternating fit from an ordered point list; the first and last points stay on the curve's ends.
ShapeRegistration Refine(const std::vector<Eigen::Vector2d>& model,
                         const std::vector<Eigen::Vector2d>& ordered, bool allow_reflection) {
  const std::vector<double> model_frac = CumulativeFractions(model);
  const std::vector<double> meas_frac = CumulativeFractions(ordered);
  std::vector<Eigen::Vector2d> targets(ordered.size());
  for (size_t k = 0; k < ordered.size(); ++k) {
    targets[k] = PointAtFraction(model, model_frac, meas_frac[k]);
  }
  // The two end points carry the scale along the strip (interior points may slide along the
  // curve); weighting them like a quarter of all points each makes the alternation converge fast.
  std::vector<double> weights(ordered.size(), 1.0);
  weights.front() = weights.back() = 0.25 * static_cast<double>(ordered.size());
  ShapeRegistration reg;
  double last_cost = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 200; ++it) {
    reg.measured_to_model = FitSimilarity(ordered, targets, allow_reflection, weights);
    reg.iterations = it + 1;
    double cost = 0.0;
    for (size_t k = 0; k < ordered.size(); ++k) {
      const Eigen::Vector2d q = reg.measured_to_model.Apply(ordered[k]);
      if (k == 0) {
        targets[k] = model.front();
      } else if (k + 1 == ordered.size()) {
        targets[k] = model.back();
      } else {
        targets[k] = ClosestOnPolyline(model, q).p;
      }
      cost += (q - targets[k]).squaredNorm();
    }
    if (std::isfinite(last_cost) && last_cost - cost <= 1e-12 * last_cost) break;
    last_cost = cost;
  }
  return reg;
}

}  // namespace

ShapeRegistration RegisterShape(const std::vector<Eigen::Vector2d>& model_m,
                                const std::vector<Eigen::Vector2d>& measured_px,
                                bool allow_reflection) {
  if (model_m.size() < 2 || measured_px.size() < 3) {
    throw std::invalid_argument("shape registration needs >= 2 model and >= 3 measured points");
  }
  CheckFinite(model_m, "model");
  CheckFinite(measured_px, "measured");

  // Order the measured points along their principal axis (a strip bent by less than 90° is a
  // graph over its chord direction).
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : measured_px) mean += p;
  mean /= static_cast<double>(measured_px.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : measured_px) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  const Eigen::Vector2d axis = eig.eigenvectors().col(1);
  if (!(eig.eigenvalues()[1] > 0.0)) {
    throw std::invalid_argument("measured points coincide");
  }
  std::vector<size_t> order(measured_px.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return (measured_px[a] - mean).dot(axis) < (measured_px[b] - mean).dot(axis);
  });

  ShapeRegistration best;
  best.rms_residual_m = std::numeric_limits<double>::infinity();
  for (int direction = 0; direction < 2; ++direction) {
    std::vector<Eigen::Vector2d> ordered;
    ordered.reserve(order.size());
    for (size_t k : order) ordered.push_back(measured_px[k]);
    ShapeRegistration reg = Refine(model_m, ordered, allow_reflection);
    double sum2 = 0.0;
    for (const auto& p : ordered) {
      const double d = ClosestOnPolyline(model_m, reg.measured_to_model.Apply(p)).distance;
      sum2 += d * d;
    }
    reg.rms_residual_m = std::sqrt(sum2 / static_cast<double>(ordered.size()));
    if (reg.rms_residual_m < best.rms_residual_m) best = reg;
    std::reverse(order.begin(), order.end());
  }
  best.residuals_m.assign(measured_px.size(), 0.0);
  for (size_t k = 0; k < measured_px.size(); ++k) {
    best.residuals_m[k] =
        ClosestOnPolyline(model_m, best.measured_to_model.Apply(measured_px[k])).distance;
    best.max_residual_m = std::max(best.max_residual_m, best.residuals_m[k]);
  }
  return best;
}

std::vector<Eigen::Vector2d> ReadPointsCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ":1:1: cannot open the file");
  std::vector<Eigen::Vector2d> points;
  std::string line;
  int line_no = 0;
  bool first_data_line = true;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    // Fields: maximal runs of characters other than separators.
    std::vector<std::pair<size_t, std::string>> fields;
    size_t k = 0;
    while (k < line.size()) {
      const size_t b = line.find_first_not_of(" \t,;", k);
      if (b == std::string::npos) break;
      const size_t e = line.find_first_of(" \t,;", b);
      fields.emplace_back(b, line.substr(b, e == std::string::npos ? std::string::npos : e - b));
      k = e == std::string::npos ? line.size() : e;
    }
    auto where = [&](size_t col) {
      return path + ":" + std::to_string(line_no) + ":" + std::to_string(col + 1) + ": ";
    };
    double v[2] = {0.0, 0.0};
    bool numeric = true;
    for (size_t f = 0; f < fields.size() && f < 2; ++f) {
      const char* b = fields[f].second.c_str();
      char* e = nullptr;
      v[f] = std::strtod(b, &e);
      if (e == b || *e != '\0' || !std::isfinite(v[f])) {
        if (first_data_line) {
          numeric = false;
          break;
        }
        throw std::invalid_argument(where(fields[f].first) + "'" + fields[f].second +
                                    "' is not a finite number");
      }
    }
    const bool header = first_data_line && !numeric;
    first_data_line = false;
    if (header) continue;
    if (fields.size() != 2) {
      throw std::invalid_argument(where(fields.size() > 2 ? fields[2].first : line.size()) +
                                  "expected two numbers x,y");
    }
    points.emplace_back(v[0], v[1]);
  }
  if (points.size() < 3) {
    throw std::invalid_argument(path + ":" + std::to_string(line_no + 1) +
                                ":1: need at least 3 points, got " + std::to_string(points.size()));
  }
  return points;
}

}  // namespace ftstack::sim::pivot
