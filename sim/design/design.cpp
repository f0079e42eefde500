#include "sim/design/design.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "sim/physical_sensor.hpp"

namespace ftstack::sim::design {

Material Steel174Ph() { return {"17-4 PH H900 stainless", 197e9, 0.27, 1170e6, 620e6, 1.0e-3}; }
Material Aluminium7075() { return {"7075-T6 aluminium", 71.7e9, 0.33, 503e6, 159e6, 1.0e-3}; }

std::string ToString(Limit l) {
  switch (l) {
    case Limit::kGaugeStrain:
      return "gauge strain";
    case Limit::kYield:
      return "yield/SF";
    case Limit::kFatigue:
      return "fatigue";
    case Limit::kBuckling:
      return "buckling/SF";
  }
  return "?";
}

double EnvelopeLoads::Max(const Row6& c) const {
  return std::hypot(c(0), c(1)) * r_[0] + std::abs(c(2)) * r_[1] + std::hypot(c(3), c(4)) * r_[2] +
         std::abs(c(5)) * r_[3];
}

double CaseLoads::Max(const Row6& c) const {
  double m = 0;
  for (const Vec6& w : cases_) m = std::max(m, std::abs(c.dot(w.transpose())));
  return m;
}

namespace {

double RowsMax(const Eigen::MatrixXd& rows, const LoadSet& loads) {
  double m = 0;
  for (Eigen::Index i = 0; i < rows.rows(); ++i) m = std::max(m, loads.Max(rows.row(i)));
  return m;
}

/// One axis alone: unit load on axis k, magnitude 1.
class AxisLoad final : public LoadSet {
 public:
  explicit AxisLoad(int k) : k_(k) {}
  [[nodiscard]] double Max(const Row6& c) const override { return std::abs(c(k_)); }

 private:
  int k_;
};

/// The commercial combined-load rule at rated ranges `rated` (see CombinedRatedMax).
class CombinedLoads final : public LoadSet {
 public:
  explicit CombinedLoads(const Vec6& rated) : rated_(rated) {}
  [[nodiscard]] double Max(const Row6& c) const override { return CombinedRatedMax(c, rated_); }

 private:
  Vec6 rated_;
};

}  // namespace

double WorstStress(const DesignModel& m, const LoadSet& loads) {
  const double s = RowsMax(m.stress_normal, loads);
  const double t = RowsMax(m.stress_shear, loads);
  return std::sqrt(s * s + 3 * t * t);
}

double WorstGaugeStrain(const DesignModel& m, const LoadSet& loads) {
  return RowsMax(m.gauge_strain, loads);
}

double WorstBucklingRatio(const DesignModel& m, const LoadSet& loads) {
  double r = 0;
  for (const BucklingCheck& b : m.buckling) r = std::max(r, loads.Max(b.axial_n) / b.critical_n);
  return r;
}

Vec6 NaturalFrequenciesHz(const Mat6& k, double mass_kg, double com_z_m, double gyration_m) {
  if (!(mass_kg > 0) || !(gyration_m > 0) || !std::isfinite(com_z_m)) {
    throw std::invalid_argument("tool mass and radius of gyration must be > 0");
  }
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();  // skew of the centre of mass (0, 0, z)
  c(0, 1) = -com_z_m;
  c(1, 0) = com_z_m;
  Mat6 m = Mat6::Zero();
  m.topLeftCorner<3, 3>() = mass_kg * Eigen::Matrix3d::Identity();
  m.topRightCorner<3, 3>() = -mass_kg * c;
  m.bottomLeftCorner<3, 3>() = mass_kg * c;
  m.bottomRightCorner<3, 3>() =
      mass_kg * gyration_m * gyration_m * Eigen::Matrix3d::Identity() - mass_kg * c * c;
  const Mat6 ks = 0.5 * (k + k.transpose());
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat6> es(ks, m);
  Vec6 f;
  for (int i = 0; i < 6; ++i)
    f(i) = std::sqrt(std::max(0.0, es.eigenvalues()(i))) / (2 * std::numbers::pi);
  return f;
}

DesignFigures Evaluate(const DesignModel& m, const DesignOptions& o) {
  DesignFigures f;
  const Material& mat = m.material;
  for (int k = 0; k < 6; ++k) {
    const AxisLoad unit(k);
    const double eps = WorstGaugeStrain(m, unit);
    const double sig = WorstStress(m, unit);
    const double buck = WorstBucklingRatio(m, unit);
    const std::array<double, 4> cap{eps > 0 ? mat.allowable_gauge_strain / eps : INFINITY,
                                    sig > 0 ? mat.yield_pa / (o.safety_factor * sig) : INFINITY,
                                    sig > 0 ? mat.fatigue_pa / sig : INFINITY,
                                    buck > 0 ? 1.0 / (o.safety_factor * buck) : INFINITY};
    const auto it = std::min_element(cap.begin(), cap.end());
    f.capacity(k) = *it;
    f.binding[static_cast<std::size_t>(k)] = static_cast<Limit>(it - cap.begin());
  }
  const CombinedLoads rated(f.capacity);
  const double use = std::max({WorstGaugeStrain(m, rated) / mat.allowable_gauge_strain,
                               WorstStress(m, rated) * o.safety_factor / mat.yield_pa,
                               WorstStress(m, rated) / mat.fatigue_pa,
                               WorstBucklingRatio(m, rated) * o.safety_factor});
  f.combined_scale = use > 1 ? 1.0 / use : 1.0;
  f.overload_margin = mat.yield_pa / WorstStress(m, CombinedLoads(f.capacity * f.combined_scale));
  // Noise: bridge noise through the least-squares calibration C = S⁺ (white noise, uncorrelated
  // channels); averaging to a lower bandwidth scales the RMS by √(B / B_native).
  f.bandwidth_hz =
      o.bandwidth_hz > 0 ? std::min(o.bandwidth_hz, m.native_bandwidth_hz) : m.native_bandwidth_hz;
  const double noise = m.bridge_noise_mvv * std::sqrt(f.bandwidth_hz / m.native_bandwidth_hz);
  const Eigen::MatrixXd cal = m.sensitivity_mvv.completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::MatrixXd cov = cal * cal.transpose();
  for (int k = 0; k < 6; ++k) f.resolution(k) = noise * std::sqrt(cov(k, k));
  f.stiffness = m.stiffness;
  f.natural_hz =
      NaturalFrequenciesHz(m.stiffness, o.tool_mass_kg, o.tool_com_z_m, o.tool_gyration_m);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(m.sensitivity_mvv * f.capacity.asDiagonal());
  const auto& sv = svd.singularValues();
  f.condition_number = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  f.force_range_n = f.capacity.head<3>().maxCoeff();
  f.tilt_capacity_nm = std::min(f.capacity(3), f.capacity(4));
  f.force_resolution_n = f.resolution.head<3>().maxCoeff();
  return f;
}

}  // namespace ftstack::sim::design
