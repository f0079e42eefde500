#include "sim/beam_root.hpp"

#include <cmath>
#include <stdexcept>

namespace ftstack::sim {

EndCompliance BuiltInRootCompliance(double e_pa, double width_m, double height_m) {
  for (double v : {e_pa, width_m, height_m}) {
    if (!std::isfinite(v) || v <= 0) {
      throw std::invalid_argument("beam root: E, width and height must be positive and finite");
    }
  }
  EndCompliance c{};
  c[4] = kOdonnellRoot / (e_pa * width_m * height_m * height_m);
  c[5] = kOdonnellRoot / (e_pa * height_m * width_m * width_m);
  return c;
}

Eigen::Matrix<double, 12, 12> WithEndCompliance(const Eigen::Matrix<double, 12, 12>& k_local,
                                                double length_m, const EndCompliance& ca,
                                                const EndCompliance& cb) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  bool any = false;
  for (std::size_t i = 0; i < 6; ++i) {
    if (!std::isfinite(ca[i]) || !std::isfinite(cb[i]) || ca[i] < 0 || cb[i] < 0) {
      throw std::invalid_argument("beam root: end compliances must be finite and >= 0");
    }
    any = any || ca[i] > 0 || cb[i] > 0;
  }
  if (!any) return k_local;
  // Rigid motion of end a carried to end b: u_b = u_a + θ_a × (L·x̂).
  Mat6 t = Mat6::Identity();
  t(1, 5) = length_m;
  t(2, 4) = -length_m;
  // Flexibility of end b relative to end a: the member (b's stiffness with a held) plus the joint
  // at b plus the joint at a, which moves the whole member rigidly under the load carried to a.
  const Mat6 f_member = k_local.bottomRightCorner<6, 6>().inverse();
  const Mat6 f = f_member +
                 t * Mat6(Eigen::Matrix<double, 6, 1>(ca.data()).asDiagonal()) * t.transpose() +
                 Mat6(Eigen::Matrix<double, 6, 1>(cb.data()).asDiagonal());
  Eigen::Matrix<double, 6, 12> d;  // relative deformation of b from the anchors' motion
  d.leftCols<6>() = -t;
  d.rightCols<6>() = Mat6::Identity();
  const Mat6 kb = f.inverse();
  return d.transpose() * kb * d;
}

}  // namespace ftstack::sim
