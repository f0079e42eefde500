#include "calibration/fit/check.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <map>

#include "calibration/fit/apply.hpp"
#include "calibration/fit/fit.hpp"

namespace ftstack::cal {
namespace {

constexpr const char* kAxis[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
constexpr const char* kUnit[6] = {"N", "N", "N", "N·m", "N·m", "N·m"};
/// A rotation about an axis is named only beyond this many σ: at 3 σ, one component in ~400
/// without a rotation would still be named (a false axis), at 4 σ one in ~16 000.
constexpr double kResolvedSigmas = 4.0;

/// K₀: how the tool's wrench follows gravity, rows Fx…Mz, columns gx gy gz.
Eigen::Matrix<double, 6, 3> ToolResponse(const CheckTool& tool) {
  Eigen::Matrix<double, 6, 3> k;
  const Eigen::Vector3d& c = tool.com_m;
  Eigen::Matrix3d cross;
  cross << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  k.topRows<3>() = tool.mass_kg * Eigen::Matrix3d::Identity();
  k.bottomRows<3>() = tool.mass_kg * cross;
  return k;
}

/// σ of the linear form vᵀk given the covariance of k.
double FormSigma(const Eigen::Vector3d& v, const Eigen::Matrix3d& cov) {
  return std::sqrt(std::max(0.0, v.dot(cov * v)));
}

/// Student's t two-sided 99 % quantile over the normal one (2.576) for ν degrees of freedom: the
/// factor that makes a σ read from ν residual degrees of freedom cover as a known σ would.
double StudentWidening(std::size_t dof) {
  static constexpr double kT995[] = {63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355,
                                     3.250,  3.169, 3.106, 3.055, 3.012, 2.977, 2.947, 2.921,
                                     2.898,  2.878, 2.861, 2.845, 2.831, 2.819, 2.807, 2.797,
                                     2.787,  2.779, 2.771, 2.763, 2.756, 2.750};
  constexpr double kZ995 = 2.5758;
  if (dof == 0) return 1e6;
  if (dof <= 30) return kT995[dof - 1] / kZ995;
  return 1.0 + 2.8 / static_cast<double>(dof);  // the quantile's 1/ν approach to 1
}

std::string Fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

std::vector<CheckPose> CheckPosesFromRecording(const CalFile& cal, const Recording& rec) {
  static const char* const kG[3] = {"gx_mps2", "gy_mps2", "gz_mps2"};
  for (const char* c : kG) (void)rec.Column(c);  // names the file when missing
  const Recording out = ApplyCalibration(cal, rec);
  const auto& status = out.Column("status");
  const std::vector<double>* pose = rec.Has("pose") ? &rec.Column("pose") : nullptr;
  std::map<double, std::size_t> index;
  std::vector<CheckPose> poses;
  std::vector<double> count;
  std::vector<Eigen::Vector3d> first_g;
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    const std::size_t line = i < rec.data_lines.size() ? rec.data_lines[i] : i + 1;
    if (status[i] != 0.0) {
      throw RecordingError(rec.path + ":" + std::to_string(line) +
                           ": the calibration flags this "
                           "row (status " +
                           Fmt("%.0f", status[i]) + "): no valid reading");
    }
    const double key = pose != nullptr ? (*pose)[i] : static_cast<double>(i);
    auto it = index.find(key);
    if (it == index.end()) it = index.emplace(key, poses.size()).first;
    if (it->second == poses.size()) {
      poses.emplace_back();
      count.push_back(0.0);
      first_g.emplace_back(rec.Column(kG[0])[i], rec.Column(kG[1])[i], rec.Column(kG[2])[i]);
    }
    CheckPose& p = poses[it->second];
    const Eigen::Vector3d gi(rec.Column(kG[0])[i], rec.Column(kG[1])[i], rec.Column(kG[2])[i]);
    if ((gi - first_g[it->second]).norm() > 0.05) {
      throw RecordingError(rec.path + ":" + std::to_string(line) +
                           ": gravity changes inside a pose by more than 0.05 m/s^2");
    }
    p.gravity_mps2 += gi;
    for (int a = 0; a < 6; ++a)
      p.reading(a) += out.Column(WrenchColumns()[static_cast<std::size_t>(a)])[i];
    count[it->second] += 1.0;
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k].gravity_mps2 /= count[k];
    poses[k].reading /= count[k];
  }
  return poses;
}

CheckResult CheckCalibration(const std::vector<CheckPose>& poses, const CheckTool& tool,
                             const std::array<double, 6>& stated_uncertainty) {
  const auto n = static_cast<Eigen::Index>(poses.size());
  if (n < 6) {
    throw std::invalid_argument("check needs at least 6 static poses, has " +
                                std::to_string(poses.size()));
  }
  if (!(tool.mass_kg > 0) || !tool.com_m.allFinite()) {
    throw std::invalid_argument("check needs a tool mass > 0 kg and a finite centre of mass");
  }
  Eigen::MatrixXd g(n, 4);
  Eigen::MatrixXd r(n, 6);
  double gmag = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const CheckPose& p = poses[static_cast<std::size_t>(i)];
    if (!p.gravity_mps2.allFinite() || !p.reading.allFinite()) {
      throw std::invalid_argument("check: pose " + std::to_string(i) + " holds NaN or infinity");
    }
    g(i, 0) = 1.0;
    g.block<1, 3>(i, 1) = p.gravity_mps2.transpose();
    r.row(i) = p.reading.transpose();
    gmag += p.gravity_mps2.norm() / static_cast<double>(n);
  }
  CheckResult res;
  res.poses = poses.size();
  Eigen::MatrixXd scaled = g;
  scaled.rightCols<3>() /= gmag > 0 ? gmag : 1.0;
  res.gravity_condition = GramCondition(scaled.transpose() * scaled);
  if (!(res.gravity_condition < 100.0)) {
    throw std::invalid_argument(
        "check: the poses' gravity directions do not span three "
        "dimensions (condition number " +
        Fmt("%.3g", res.gravity_condition) + "); tilt the tool about two axes");
  }
  const Eigen::Matrix4d inv = (g.transpose() * g).inverse();
  const Eigen::MatrixXd theta = inv * g.transpose() * r;  // 4 × 6
  const Eigen::MatrixXd resid = g * theta - r;
  const Eigen::Matrix<double, 6, 3> k0 = ToolResponse(tool);
  const double load[2] = {tool.mass_kg, tool.mass_kg * tool.com_m.norm()};
  res.bias = theta.row(0).transpose();
  std::array<Eigen::Matrix3d, 6> cov{};
  std::ostringstream failed;
  const auto dof = static_cast<std::size_t>(std::max<Eigen::Index>(0, n - 4));
  res.residual_dof = dof;
  // What a pose-angle error θ does to a reading: F moves by m·|g|·θ, M by m·|c|·|g|·θ.
  const double angle_sd[2] = {tool.mass_kg * gmag * tool.pose_angle_sigma_rad,
                              tool.mass_kg * tool.com_m.norm() * gmag * tool.pose_angle_sigma_rad};
  for (int a = 0; a < 6; ++a) {
    AxisCheck& ax = res.axes[static_cast<std::size_t>(a)];
    const double scatter =
        resid.col(a).squaredNorm() / static_cast<double>(std::max<std::size_t>(1, dof));
    const double prior = angle_sd[a / 3] * angle_sd[a / 3];
    const double widen = StudentWidening(dof);
    const double var = scatter > prior ? scatter * widen * widen : prior;
    cov[static_cast<std::size_t>(a)] = var * inv.bottomRightCorner<3, 3>();
    const Eigen::Matrix3d& c = cov[static_cast<std::size_t>(a)];
    const Eigen::Vector3d k = theta.block<3, 1>(1, a);
    const Eigen::Vector3d e = k0.row(a).transpose();
    const Eigen::Vector3d d = k - e;
    ax.residual_rms = std::sqrt(resid.col(a).squaredNorm() / static_cast<double>(n));
    ax.gain_excited = e.norm() >= 0.01 * load[a / 3] && e.norm() > 0;
    Eigen::Vector3d cross_part = d;
    if (ax.gain_excited) {
      ax.gain_error = d.dot(e) / e.squaredNorm();
      // The stated mass scales every row of K₀; a centre-of-mass error moves a moment row by
      // m·δc, of which the part along the row is a gain error.
      const double rel_mass = tool.mass_sigma_kg / tool.mass_kg;
      const double rel_com = a >= 3 ? tool.mass_kg * tool.com_sigma_m / e.norm() : 0.0;
      ax.gain_sigma = std::sqrt(std::pow(FormSigma(e, c) / e.squaredNorm(), 2) +
                                rel_mass * rel_mass + rel_com * rel_com);
      cross_part = d - ax.gain_error * e;
    }
    ax.crosstalk = cross_part.norm() * gmag;
    ax.crosstalk_sigma = cross_part.norm() > 0 ? FormSigma(cross_part.normalized(), c) * gmag : 0;
    ax.worst_error = d.norm() * gmag;
    ax.worst_sigma = d.norm() > 0 ? FormSigma(d.normalized(), c) * gmag : 0;
    const double stated = gmag * (a < 3 ? tool.mass_sigma_kg
                                        : std::hypot(tool.mass_sigma_kg * tool.com_m.norm(),
                                                     tool.mass_kg * tool.com_sigma_m));
    ax.worst_sigma = std::hypot(ax.worst_sigma, stated);
    ax.crosstalk_sigma =
        std::hypot(ax.crosstalk_sigma, a < 3 ? 0.0 : gmag * tool.mass_kg * tool.com_sigma_m);
    ax.allowed = 2.0 * stated_uncertainty[static_cast<std::size_t>(a)];
    const bool beyond = ax.worst_error - 3.0 * ax.worst_sigma > ax.allowed;
    const bool misfit = ax.allowed > 0 && ax.residual_rms > ax.allowed;
    ax.pass = !beyond && !misfit;
    if (!ax.pass) {
      failed << (res.pass ? "" : "; ") << kAxis[a] << " error " << Fmt("%.3g", ax.worst_error)
             << " ± " << Fmt("%.2g", ax.worst_sigma) << " " << kUnit[a]
             << (misfit ? " (does not follow gravity linearly)" : "") << " > "
             << Fmt("%.3g", ax.allowed) << " " << kUnit[a] << " allowed";
      res.pass = false;
    }
  }
  // R ≈ I + [ω]× in the force block: ω from its antisymmetric part.
  const Eigen::Matrix3d kf = theta.block<3, 3>(1, 0).transpose() / tool.mass_kg;
  res.rotation_rad = {(kf(2, 1) - kf(1, 2)) / 2, (kf(0, 2) - kf(2, 0)) / 2,
                      (kf(1, 0) - kf(0, 1)) / 2};
  const auto var_of = [&](int row, int col) {
    return cov[static_cast<std::size_t>(row)](col, col) / (tool.mass_kg * tool.mass_kg);
  };
  res.rotation_sigma_rad = {std::sqrt(var_of(2, 1) + var_of(1, 2)) / 2,
                            std::sqrt(var_of(0, 2) + var_of(2, 0)) / 2,
                            std::sqrt(var_of(1, 0) + var_of(0, 1)) / 2};
  for (int i = 0; i < 3; ++i) {
    res.rotation_resolved[static_cast<std::size_t>(i)] =
        std::abs(res.rotation_rad(i)) > kResolvedSigmas * res.rotation_sigma_rad(i);
  }
  res.verdict = res.pass ? "PASS: every axis within 2 x the calibration's stated uncertainty"
                         : "FAIL: " + failed.str();
  return res;
}

std::string CheckSummary(const CheckResult& r, const CheckTool& tool) {
  std::ostringstream o;
  o << "tool " << Fmt("%.4g", tool.mass_kg) << " kg, centre of mass " << Fmt("%.4g", tool.com_m.x())
    << " " << Fmt("%.4g", tool.com_m.y()) << " " << Fmt("%.4g", tool.com_m.z()) << " m; " << r.poses
    << " poses, gravity condition number " << Fmt("%.3g", r.gravity_condition) << "\n";
  o << "axis  gain error (1 sigma)     cross-talk (1 sigma)     worst error (1 sigma)    "
       "residual    allowed\n";
  for (std::size_t a = 0; a < 6; ++a) {
    const AxisCheck& x = r.axes[a];
    char line[256];
    const std::string gain = x.gain_excited ? Fmt("%+8.3f%%", x.gain_error * 100) + " ± " +
                                                  Fmt("%.3f%%", x.gain_sigma * 100)
                                            : std::string("not excited         ");
    std::snprintf(line, sizeof line,
                  "%-4s  %-22s  %9.3g ± %-8.2g %-4s %9.3g ± %-8.2g  %9.3g  %9.3g  %s\n", kAxis[a],
                  gain.c_str(), x.crosstalk, x.crosstalk_sigma, kUnit[a], x.worst_error,
                  x.worst_sigma, x.residual_rms, x.allowed, x.pass ? "ok" : "FAIL");
    o << line;
  }
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  o << "frame rotation seen in the forces: " << Fmt("%+.3f", r.rotation_rad.x() * kDeg) << " ± "
    << Fmt("%.3f", r.rotation_sigma_rad.x() * kDeg) << ", "
    << Fmt("%+.3f", r.rotation_rad.y() * kDeg) << " ± "
    << Fmt("%.3f", r.rotation_sigma_rad.y() * kDeg) << ", "
    << Fmt("%+.3f", r.rotation_rad.z() * kDeg) << " ± "
    << Fmt("%.3f", r.rotation_sigma_rad.z() * kDeg) << " deg about x, y, z";
  std::string named;
  for (std::size_t i = 0; i < 3; ++i) {
    if (r.rotation_resolved[i]) named += std::string(named.empty() ? "" : ", ") + "xyz"[i];
  }
  o << (named.empty() ? " (no rotation resolved beyond 4 sigma)"
                      : " (resolved about " + named + ")")
    << "\n";
  if (r.residual_dof < 8) {
    o << "only " << r.poses << " poses: sigmas read from " << r.residual_dof
      << " residual degrees of freedom, widened by Student's t\n";
  }
  o << r.verdict << "\n";
  return o.str();
}

}  // namespace ftstack::cal
