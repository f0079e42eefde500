#include "sim/design/frame.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace ftstack::sim::design {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& p) {
  Eigen::Matrix3d s;
  s << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
  return s;
}

}  // namespace

Eigen::Matrix3d ElementRotation(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                const Eigen::Vector3d& z_hint) {
  const Eigen::Vector3d x = (q - p).normalized();
  Eigen::Vector3d z = z_hint - z_hint.dot(x) * x;
  if (!(z.norm() > 1e-9)) throw std::invalid_argument("frame: z_hint is parallel to the element");
  z.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.row(0) = x.transpose();
  r.row(1) = y.transpose();
  r.row(2) = z.transpose();
  return r;
}

double RectangleTorsionShearPerNm(double side1_m, double side2_m) {
  const double a = 0.5 * std::max(side1_m, side2_m);
  const double b = 0.5 * std::min(side1_m, side2_m);
  const double r = b / a;
  return 3.0 / (8.0 * a * b * b) *
         (1 + 0.6095 * r + 0.8865 * r * r - 1.8023 * r * r * r + 0.9100 * r * r * r * r);
}

double PlateFactor(double length_m, double width_m, double height_m, double poisson) {
  return std::max(width_m, height_m) > length_m ? 1.0 / (1.0 - poisson * poisson) : 1.0;
}

std::string SlenderBeamViolation(double length_m, double width_m, double height_m) {
  const double t = std::min(width_m, height_m);
  const double b = std::max(width_m, height_m);
  char buf[96];
  if (b >= 5 * t) {  // a leaf: slender through its thickness, a deep beam in its plane
    if (length_m < 2 * t) {
      std::snprintf(buf, sizeof buf, "L/t = %.2f < 2", length_m / t);
      return buf;
    }
    if (length_m < 0.5 * b) {
      std::snprintf(buf, sizeof buf, "L/b = %.2f < 0.5", length_m / b);
      return buf;
    }
    return "";
  }
  if (length_m < 2 * b) {
    std::snprintf(buf, sizeof buf, "L/h = %.2f < 2", length_m / b);
    return buf;
  }
  return "";
}

int FrameSolution::DofOf(const Anchor& a) const {
  if (a.body >= 0) return a.body == kGround ? -1 : 6 * (a.body - 1);
  return 6 * (m_.body_count - 1) + 6 * a.node;
}

Mat6 FrameSolution::EndMap(const Anchor& a, const Eigen::Matrix3d& r) const {
  Mat6 rb = Mat6::Zero();
  rb.topLeftCorner<3, 3>() = r;
  rb.bottomRightCorner<3, 3>() = r;
  if (a.body < 0) return rb;
  Mat6 t = Mat6::Identity();  // rigid body about the origin: u(p) = u0 + θ × p
  t.topRightCorner<3, 3>() = -Skew(a.point_m);
  return rb * t;
}

FrameSolution::FrameSolution(FrameModel model) : m_(std::move(model)) {
  if (m_.body_count < 2) throw std::invalid_argument("frame: need the ground and the platform");
  const int nodes = static_cast<int>(m_.nodes_m.size());
  auto check = [&](const Anchor& a) {
    if (a.body >= m_.body_count || (a.body < 0 && (a.node < 0 || a.node >= nodes))) {
      throw std::invalid_argument("frame: an element end names no body or node");
    }
  };
  const int n = 6 * (m_.body_count - 1) + 6 * nodes;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  std::vector<std::array<Mat6, 2>> maps;
  el_.resize(m_.elements.size());
  for (std::size_t e = 0; e < m_.elements.size(); ++e) {
    const FrameElement& fe = m_.elements[e];
    check(fe.a);
    check(fe.b);
    const Eigen::Vector3d p = EndPoint(static_cast<int>(e), false);
    const Eigen::Vector3d q = EndPoint(static_cast<int>(e), true);
    ElementData& d = el_[e];
    d.length = (q - p).norm();
    d.section = RectangularSection(m_.e_pa, m_.poisson, fe.width_m, fe.height_m);
    if (m_.shear_deformable) {
      // The plate factor stiffens bending through the thin side; for a leaf that is local y
      // (height is the thickness) — a wide member with height > width is not a leaf.
      const double member = fe.member_length_m > 0 ? fe.member_length_m : d.length;
      d.plate = fe.width_m >= fe.height_m ? PlateFactor(member, fe.width_m, fe.height_m, m_.poisson)
                                          : 1.0;
      d.section.iy_m4 *= d.plate;
      d.k_local = TimoshenkoElementStiffness(d.section, d.length);
    } else {
      d.k_local = FrameElementStiffness(d.section, d.length);
    }
    d.k_local = WithEndCompliance(d.k_local, d.length, fe.joint_a, fe.joint_b);
    const Eigen::Matrix3d r = ElementRotation(p, q, fe.z_hint);
    const std::array<Mat6, 2> map{EndMap(fe.a, r), EndMap(fe.b, r)};
    maps.push_back(map);
    const int dof[2] = {DofOf(fe.a), DofOf(fe.b)};
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        if (dof[i] < 0 || dof[j] < 0) continue;
        k.block<6, 6>(dof[i], dof[j]) +=
            map[i].transpose() * d.k_local.block<6, 6>(6 * i, 6 * j) * map[j];
      }
    }
  }
  for (const NodeSpring& s : m_.springs) {
    const int d = DofOf(Anchor{-1, s.node, Eigen::Vector3d::Zero()});
    k.block<6, 6>(d, d) += s.k;
  }
  Eigen::MatrixXd f = Eigen::MatrixXd::Zero(n, 6);
  f.topRows<6>().setIdentity();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(k);
  u_ = ldlt.solve(f);
  const double scale = k.norm() * u_.norm() + f.norm();
  if (!u_.allFinite() || !((k * u_ - f).norm() <= 1e-8 * scale)) {
    throw std::invalid_argument(
        "frame: the structure is a mechanism (singular stiffness; residual " +
        std::to_string((k * u_ - f).norm() / scale) + ")");
  }
  c_platform_ = u_.topRows<6>();
  c_platform_ = 0.5 * (c_platform_ + c_platform_.transpose()).eval();
  k_platform_ = c_platform_.inverse();
  for (std::size_t e = 0; e < el_.size(); ++e) {
    const FrameElement& fe = m_.elements[e];
    Eigen::Matrix<double, 12, 6> ul = Eigen::Matrix<double, 12, 6>::Zero();
    const int dof[2] = {DofOf(fe.a), DofOf(fe.b)};
    for (int i = 0; i < 2; ++i) {
      if (dof[i] >= 0)
        ul.middleRows<6>(6 * i) = maps[e][static_cast<std::size_t>(i)] * u_.middleRows<6>(dof[i]);
    }
    el_[e].end_forces = el_[e].k_local * ul;
  }
}

Eigen::Vector3d FrameSolution::EndPoint(int element, bool end_b) const {
  const FrameElement& fe = m_.elements.at(static_cast<std::size_t>(element));
  const Anchor& a = end_b ? fe.b : fe.a;
  return a.body >= 0 ? a.point_m : m_.nodes_m.at(static_cast<std::size_t>(a.node));
}

double FrameSolution::Length(int element) const {
  return el_.at(static_cast<std::size_t>(element)).length;
}

const BeamSection& FrameSolution::Section(int element) const {
  return el_.at(static_cast<std::size_t>(element)).section;
}

SectionRows FrameSolution::SectionAt(int element, double s) const {
  const ElementData& d = el_.at(static_cast<std::size_t>(element));
  if (!std::isfinite(s) || s < 0 || s > d.length * (1 + 1e-12)) {
    throw std::invalid_argument("frame: position " + std::to_string(s) + " m is off element " +
                                std::to_string(element));
  }
  const auto& e = d.end_forces;
  SectionRows m;
  m.row(0) = -e.row(0);
  m.row(1) = -e.row(1);
  m.row(2) = -e.row(2);
  m.row(3) = -e.row(3);
  m.row(4) = -e.row(4) - s * e.row(2);
  m.row(5) = -e.row(5) + s * e.row(1);
  return m;
}

Row6 FrameSolution::AxialStrain(int element, double s_m, double y_m, double z_m) const {
  const SectionRows sec = SectionAt(element, s_m);
  const BeamSection& sc = Section(element);
  return (sec.row(0) / sc.area_m2 + sec.row(4) * (z_m / sc.iy_m4) - sec.row(5) * (y_m / sc.iz_m4)) /
         sc.e_pa;
}

Row6 FrameSolution::NormalStress(int element, double s_m, double y_m, double z_m) const {
  const SectionRows sec = SectionAt(element, s_m);
  const BeamSection& sc = Section(element);
  const double iy = sc.iy_m4 / el_.at(static_cast<std::size_t>(element)).plate;
  return sec.row(0) / sc.area_m2 + sec.row(4) * (z_m / iy) - sec.row(5) * (y_m / sc.iz_m4);
}

}  // namespace ftstack::sim::design
