#include "calibration/fit/payload.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ftstack::cal {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

Eigen::Matrix3d Skew(const Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

Vector3d Gravity(const PayloadReading& r) {
  return {r.gravity_mps2[0], r.gravity_mps2[1], r.gravity_mps2[2]};
}

template <typename... Args>
std::string Fmt(const char* f, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, args...);
  return buf;
}

/// "(0.00, 0.00, 1.00) (the sensor's z axis)" for a unit direction.
std::string Direction(const Vector3d& d) {
  static const char* const kAxis[3] = {"x", "y", "z"};
  std::string s = Fmt("(%.2f, %.2f, %.2f)", d.x(), d.y(), d.z());
  Eigen::Index k = 0;
  if (d.cwiseAbs().maxCoeff(&k) > 0.95) s += std::string(" (the sensor's ") + kAxis[k] + " axis)";
  return s;
}

/// The sensor axis most perpendicular to d, as "x", "y" or "z".
std::string MostPerpendicularAxis(const Vector3d& d) {
  static const char* const kAxis[3] = {"x", "y", "z"};
  Eigen::Index k = 0;
  (void)d.cwiseAbs().minCoeff(&k);
  return kAxis[k];
}

/// Spread of the gravity directions: the largest angle between any reading's and the mean.
double SpreadDeg(const std::vector<PayloadReading>& rs, Vector3d* mean_dir) {
  Vector3d mean = Vector3d::Zero();
  for (const auto& r : rs) mean += Gravity(r).normalized();
  *mean_dir = mean.norm() > 1e-12 ? Vector3d(mean.normalized()) : Vector3d::UnitZ();
  double worst = 0;
  for (const auto& r : rs) {
    const double c = std::clamp(Gravity(r).normalized().dot(*mean_dir), -1.0, 1.0);
    worst = std::max(worst, std::acos(c) * 180.0 / M_PI);
  }
  return worst;
}

double Condition(const MatrixXd& a, Eigen::JacobiSVD<MatrixXd>* svd) {
  *svd = Eigen::JacobiSVD<MatrixXd>(a, Eigen::ComputeFullV);
  const VectorXd& s = svd->singularValues();
  const double smin = s(s.size() - 1);
  return smin > 0 ? s(0) / smin : INFINITY;
}

struct Block {
  VectorXd params;
  MatrixXd cov;
  double rms = 0;
  double condition = 0;
};

/// Solves one block a·p = b; the condition check uses the column-scaled design `scaled`.
Block Solve(const MatrixXd& a, const VectorXd& b, double condition) {
  Block out;
  out.condition = condition;
  const auto qr = a.colPivHouseholderQr();
  out.params = qr.solve(b);
  const VectorXd res = b - a * out.params;
  const double dof = static_cast<double>(a.rows() - a.cols());
  const double var = res.squaredNorm() / dof;
  out.rms = std::sqrt(res.squaredNorm() / static_cast<double>(a.rows()));
  out.cov = var * (a.transpose() * a).inverse();
  return out;
}

void CheckInput(const std::vector<PayloadReading>& rs) {
  if (rs.size() < 3) {
    throw PayloadIdentError(
        "payload identification needs at least 3 static readings in "
        "different orientations (got " +
        std::to_string(rs.size()) + ")");
  }
  for (std::size_t i = 0; i < rs.size(); ++i) {
    bool finite = true;
    for (double v : rs[i].gravity_mps2) finite = finite && std::isfinite(v);
    for (double v : rs[i].wrench) finite = finite && std::isfinite(v);
    if (!finite) {
      throw PayloadIdentError("reading " + std::to_string(i + 1) + ": NaN or infinity");
    }
    const double g = Gravity(rs[i]).norm();
    if (!(g > 1.0 && g < 50.0)) {
      throw PayloadIdentError("reading " + std::to_string(i + 1) +
                              Fmt(": |gravity| = %.3g m/s² is not a gravity vector", g));
    }
  }
}

}  // namespace

PayloadFit FitPayload(const std::vector<PayloadReading>& rs, const PayloadFitOptions& options) {
  CheckInput(rs);
  const Eigen::Index n = static_cast<Eigen::Index>(rs.size());
  double gnorm = 0;
  for (const auto& r : rs) gnorm += Gravity(r).norm() / static_cast<double>(n);
  MatrixXd af(3 * n, 4), am(3 * n, 6);
  VectorXd bf(3 * n), bm(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& r = rs[static_cast<std::size_t>(i)];
    const Vector3d g = Gravity(r);
    af.block(3 * i, 0, 3, 1) = g;
    af.block(3 * i, 1, 3, 3).setIdentity();
    am.block(3 * i, 0, 3, 3) = -Skew(g);  // (m·c) × g = −[g]× (m·c)
    am.block(3 * i, 3, 3, 3).setIdentity();
    for (int k = 0; k < 3; ++k) {
      bf(3 * i + k) = r.wrench[static_cast<std::size_t>(k)];
      bm(3 * i + k) = r.wrench[static_cast<std::size_t>(3 + k)];
    }
  }
  MatrixXd sf = af, sm = am;
  sf.col(0) /= gnorm;
  sm.leftCols(3) /= gnorm;
  Eigen::JacobiSVD<MatrixXd> svd_f, svd_m;
  const double cf = Condition(sf, &svd_f);
  const double cm = Condition(sm, &svd_m);
  std::string why;
  Vector3d mean_dir;
  const double spread = SpreadDeg(rs, &mean_dir);
  if (cf > options.max_condition) {
    why +=
        Fmt("mass is not identifiable (not separable from the force bias along %s): gravity "
            "points nearly the same way in every reading (largest angle from the mean %.2g°); "
            "add",
            Direction(mean_dir).c_str(), spread);
    why += " poses with gravity at least 30° away, e.g. gravity along the sensor's " +
           MostPerpendicularAxis(mean_dir) + " axis. ";
  }
  const VectorXd& s = svd_m.singularValues();
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    if (!(s(k) * options.max_condition < s(0))) continue;
    const Vector3d d = svd_m.matrixV().col(k).head(3);
    if (d.norm() < 0.3) continue;  // a bias direction alone cannot be unidentifiable
    const Vector3d u = d.normalized();
    why += "centre of mass along " + Direction(u) +
           " is not identifiable (not separable from the moment bias): the gravity vectors "
           "differ only along that direction; add a pose with gravity tilted away from it, "
           "e.g. gravity along the sensor's " +
           MostPerpendicularAxis(u) + " axis. ";
  }
  if (!why.empty()) {
    why += Fmt("(condition numbers: force %.3g, moment %.3g; limit %.3g)", cf, cm,
               options.max_condition);
    throw PayloadIdentError(why);
  }
  const Block f = Solve(af, bf, cf);
  const Block m = Solve(am, bm, cm);
  PayloadFit fit;
  fit.force_condition = cf;
  fit.moment_condition = cm;
  fit.force_cov = f.cov;
  fit.moment_cov = m.cov;
  PayloadFile& p = fit.file;
  const double mass = f.params(0);
  if (!(mass > 0)) {
    throw PayloadIdentError(
        Fmt("identified mass %.3g kg is not positive: check the sign of "
            "the gravity vectors (gravity points down, towards the earth)",
            mass));
  }
  const Vector3d mc = m.params.head(3);
  const Vector3d c = mc / mass;
  // c = (m·c)/m: J = [−mc/m², I/m]; m and m·c come from independent blocks.
  const Eigen::Matrix3d cov_c = m.cov.topLeftCorner(3, 3) / (mass * mass) +
                                (mc * mc.transpose()) * f.cov(0, 0) / std::pow(mass, 4);
  p.mass_kg = mass;
  p.mass_sigma_kg = std::sqrt(f.cov(0, 0));
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    p.com_m[i] = c(k);
    p.com_sigma_m[i] = std::sqrt(cov_c(k, k));
    p.force_bias_n[i] = f.params(1 + k);
    p.force_bias_sigma_n[i] = std::sqrt(f.cov(1 + k, 1 + k));
    p.moment_bias_nm[i] = m.params(3 + k);
    p.moment_bias_sigma_nm[i] = std::sqrt(m.cov(3 + k, 3 + k));
  }
  p.readings = rs.size();
  p.force_rms_n = f.rms;
  p.moment_rms_nm = m.rms;
  return fit;
}

std::vector<PayloadReading> PayloadReadingsFromRecording(const Recording& rec) {
  static const char* const kG[3] = {"gx_mps2", "gy_mps2", "gz_mps2"};
  std::vector<PayloadReading> out(rec.rows());
  for (std::size_t k = 0; k < 3; ++k) {
    const std::vector<double>& col = rec.Column(kG[k]);
    for (std::size_t i = 0; i < col.size(); ++i) out[i].gravity_mps2[k] = col[i];
  }
  for (std::size_t a = 0; a < 6; ++a) {
    const std::vector<double>& col = rec.Column(WrenchColumns()[a]);
    for (std::size_t i = 0; i < col.size(); ++i) out[i].wrench[a] = col[i];
  }
  return out;
}

std::string PayloadSummary(const PayloadFit& fit) {
  const PayloadFile& p = fit.file;
  std::string s;
  s += Fmt("mass %.6g ± %.2g kg\n", p.mass_kg, p.mass_sigma_kg);
  s += Fmt("centre of mass x %.3f  y %.3f  z %.3f mm", p.com_m[0] * 1e3, p.com_m[1] * 1e3,
           p.com_m[2] * 1e3);
  s += Fmt("  (± %.3f, %.3f, %.3f mm)\n", p.com_sigma_m[0] * 1e3, p.com_sigma_m[1] * 1e3,
           p.com_sigma_m[2] * 1e3);
  s += Fmt("force bias %.4f %.4f %.4f N", p.force_bias_n[0], p.force_bias_n[1], p.force_bias_n[2]);
  s += Fmt("  (± %.2g, %.2g, %.2g N)\n", p.force_bias_sigma_n[0], p.force_bias_sigma_n[1],
           p.force_bias_sigma_n[2]);
  s += Fmt("moment bias %.5f %.5f %.5f N·m", p.moment_bias_nm[0], p.moment_bias_nm[1],
           p.moment_bias_nm[2]);
  s += Fmt("  (± %.2g, %.2g, %.2g N·m)\n", p.moment_bias_sigma_nm[0], p.moment_bias_sigma_nm[1],
           p.moment_bias_sigma_nm[2]);
  s += Fmt("%zu readings; residual RMS %.3g N, %.3g N·m", p.readings, p.force_rms_n,
           p.moment_rms_nm);
  s += Fmt("; condition numbers force %.3g, moment %.3g\n", fit.force_condition,
           fit.moment_condition);
  return s;
}

}  // namespace ftstack::cal
