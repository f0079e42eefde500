#include "calibration/fit/known_mass.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

namespace ftstack::cal {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

std::string Where(const Recording& rec, std::size_t row, const char* column) {
  const std::string line =
      row < rec.data_lines.size() ? std::to_string(rec.data_lines[row]) : std::to_string(row + 1);
  return rec.path + ":" + line + ": field " + std::to_string(rec.Find(column) + 1) + " (" + column +
         ")";
}

Vector3d Gravity(const Recording& rec, std::size_t i) {
  return {rec.Column("gx_mps2")[i], rec.Column("gy_mps2")[i], rec.Column("gz_mps2")[i]};
}

/// Row r's jig load on axis a as a linear function of p = (m_j, m_j·c_j): coefficients.
Eigen::Matrix<double, 6, 4> JigRows(const Vector3d& g) {
  Eigen::Matrix<double, 6, 4> j = Eigen::Matrix<double, 6, 4>::Zero();
  j.block<3, 1>(0, 0) = g;
  // (m·c) × g = −[g]× (m·c)
  j(3, 2) = g.z();
  j(3, 3) = -g.y();
  j(4, 1) = -g.z();
  j(4, 3) = g.x();
  j(5, 1) = g.y();
  j(5, 2) = -g.x();
  return j;
}

const char* const kParam[4] = {"mass", "centre of mass along x", "centre of mass along y",
                               "centre of mass along z"};

}  // namespace

bool IsKnownMassRecording(const Recording& rec) { return rec.Has("mass_kg"); }

Recording WithReferenceFromMasses(const Recording& rec) {
  for (const char* c : kKnownMassColumns) (void)rec.Column(c);  // throws naming the file
  Recording out = rec;
  std::vector<std::vector<double>> w(6, std::vector<double>(rec.rows()));
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    const double m = rec.Column("mass_kg")[i];
    if (!(m >= 0)) throw RecordingError(Where(rec, i, "mass_kg") + ": negative mass");
    const Vector3d g = Gravity(rec, i);
    if (!(g.norm() >= 1.0 && g.norm() <= 50.0)) {
      throw RecordingError(Where(rec, i, "gx_mps2") + ": |g| is not a gravity vector");
    }
    const Vector3d arm(rec.Column("arm_x_m")[i], rec.Column("arm_y_m")[i],
                       rec.Column("arm_z_m")[i]);
    const Vector3d f = m * g;
    const Vector3d mo = arm.cross(f);
    for (int k = 0; k < 3; ++k) {
      w[static_cast<std::size_t>(k)][i] = f(k);
      w[static_cast<std::size_t>(3 + k)][i] = mo(k);
    }
  }
  for (std::size_t a = 0; a < 6; ++a) out.SetColumn(WrenchColumns()[a], std::move(w[a]));
  out.metadata.push_back("reference: from mass_kg, arm_*_m and g*_mps2 (ftcal)");
  return out;
}

namespace {

/// The jig's columns and the reference per axis with the calibration's span [1, b] projected out;
/// `energy` is each jig column's squared norm before the projection.
struct Projected {
  std::array<MatrixXd, 6> a;
  std::array<VectorXd, 6> w;
  std::array<Eigen::Vector4d, 6> energy;
};

Projected Project(const Recording& rec) {
  const std::size_t n = rec.rows();
  const std::size_t nb = rec.BridgeCount();
  if (nb == 0) throw RecordingError(rec.path + ": no bridge columns b0 …");
  MatrixXd x(static_cast<Index>(n), static_cast<Index>(nb + 1));
  for (std::size_t i = 0; i < n; ++i) {
    x(static_cast<Index>(i), 0) = 1.0;
    for (std::size_t c = 0; c < nb; ++c) {
      x(static_cast<Index>(i), static_cast<Index>(c + 1)) = rec.Column("b" + std::to_string(c))[i];
    }
  }
  const Eigen::HouseholderQR<MatrixXd> qr(x);
  const MatrixXd q = qr.householderQ() * MatrixXd::Identity(x.rows(), x.cols());
  auto project = [&](const VectorXd& v) -> VectorXd { return v - q * (q.transpose() * v); };
  Projected out;
  for (std::size_t ax = 0; ax < 6; ++ax) {
    MatrixXd j(static_cast<Index>(n), 4);
    VectorXd ref(static_cast<Index>(n));
    for (std::size_t i = 0; i < n; ++i) {
      j.row(static_cast<Index>(i)) = JigRows(Gravity(rec, i)).row(static_cast<Index>(ax));
      ref(static_cast<Index>(i)) = rec.Column(WrenchColumns()[ax])[i];
    }
    out.a[ax] = MatrixXd(j.rows(), 4);
    for (int k = 0; k < 4; ++k) {
      out.energy[ax](k) = j.col(k).squaredNorm();
      out.a[ax].col(k) = project(j.col(k));
    }
    out.w[ax] = project(ref);
  }
  return out;
}

/// Refuses a jig the holds cannot separate from the calibration; returns the condition number of
/// the normalised normal matrix and *worst, the least surviving share of a jig column.
double CheckIdentifiable(const Eigen::Matrix4d& h, const Eigen::Vector4d& raw, double* worst) {
  std::string why;
  *worst = 1;
  for (int k = 0; k < 4; ++k) {
    const double frac = raw(k) > 0 ? h(k, k) / raw(k) : 0.0;
    *worst = std::min(*worst, frac);
    if (frac < 1e-6) {
      why += std::string("the jig's ") + kParam[k] +
             " is not identifiable: its load is explained by the calibration's offsets (gravity "
             "keeps the same direction in the sensor frame in every hold, or never varies across "
             "that axis); add holds in other orientations. ";
    }
  }
  if (!why.empty()) throw JigIdentError(why);
  const Eigen::Vector4d d = h.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix4d hn = d.asDiagonal() * h * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(hn);
  const double cond = eig.eigenvalues()(3) / std::max(eig.eigenvalues()(0), 1e-300);
  if (cond > 1e6) {
    Index k = 0;
    (void)eig.eigenvectors().col(0).cwiseAbs().maxCoeff(&k);
    char buf[96];
    std::snprintf(buf, sizeof buf, " (condition number %.3g)", cond);
    throw JigIdentError(std::string("the jig's ") + kParam[k] +
                        " is not separable from the calibration" + buf +
                        ": vary the orientation more (gravity along x, y and z of the sensor)");
  }
  return cond;
}

}  // namespace

JigEstimate IdentifyJig(const Recording& rec) {
  const Projected pr = Project(rec);
  const double n = static_cast<double>(rec.rows());
  std::array<double, 6> weight{1, 1, 1, 1, 1, 1};
  JigEstimate est;
  Eigen::Matrix4d h;
  Eigen::Vector4d p;
  double rss = 0;
  for (int pass = 0; pass < 2; ++pass) {  // pass 2 weights each axis by 1/σ of pass 1
    h.setZero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero(), raw = Eigen::Vector4d::Zero();
    for (std::size_t ax = 0; ax < 6; ++ax) {
      const double w2 = weight[ax] * weight[ax];
      h += w2 * pr.a[ax].transpose() * pr.a[ax];
      rhs += w2 * pr.a[ax].transpose() * pr.w[ax];
      raw += w2 * pr.energy[ax];
    }
    est.condition = CheckIdentifiable(h, raw, &est.surviving_fraction_min);
    p = -h.ldlt().solve(rhs);
    rss = 0;
    for (std::size_t ax = 0; ax < 6; ++ax) {
      const double s2 = (pr.w[ax] + pr.a[ax] * p).squaredNorm() / n;
      rss += weight[ax] * weight[ax] * s2 * n;
      if (pass == 0) weight[ax] = 1.0 / std::sqrt(std::max(s2, 1e-300));
    }
  }
  const double dof = 6.0 * n - 6.0 * static_cast<double>(rec.BridgeCount() + 1) - 4.0;
  const Eigen::Matrix4d cov = (rss / dof) * h.inverse();
  const double m = p(0);
  if (!(m > 0)) throw JigIdentError("the identified jig mass is not positive: check g's sign");
  est.mass_kg = m;
  est.mass_sigma_kg = std::sqrt(cov(0, 0));
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    est.com_m[i] = p(1 + k) / m;
    // c = (m·c)/m, first order: J = [−(m·c)/m², 1/m].
    const double var = cov(1 + k, 1 + k) / (m * m) +
                       std::pow(p(1 + k), 2) * cov(0, 0) / std::pow(m, 4) -
                       2.0 * p(1 + k) * cov(0, 1 + k) / std::pow(m, 3);
    est.com_sigma_m[i] = std::sqrt(std::max(var, 0.0));
  }
  return est;
}

Recording WithJig(const Recording& rec, const JigEstimate& jig) {
  Recording out = rec;
  const Eigen::Vector4d p(jig.mass_kg, jig.mass_kg * jig.com_m[0], jig.mass_kg * jig.com_m[1],
                          jig.mass_kg * jig.com_m[2]);
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    const Eigen::Matrix<double, 6, 1> add = JigRows(Gravity(rec, i)) * p;
    for (std::size_t a = 0; a < 6; ++a) {
      out.Column(WrenchColumns()[a])[i] += add(static_cast<Index>(a));
    }
  }
  char buf[160];
  std::snprintf(buf, sizeof buf, "jig: %.6g kg at (%.6g, %.6g, %.6g) m, added to the reference",
                jig.mass_kg, jig.com_m[0], jig.com_m[1], jig.com_m[2]);
  out.metadata.push_back(buf);
  return out;
}

}  // namespace ftstack::cal
