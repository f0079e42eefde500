#include "sim/flexure_body.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sim/beam_root.hpp"

namespace ftstack::sim {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& p) {
  Eigen::Matrix3d s;
  s << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
  return s;
}

bool Finite(double v) { return std::isfinite(v); }

/// Torsional shear at the middle of the long and short sides of a rectangle, per N·m of torque.
/// Long side: Roark, Table 10.7 case 4, τ = 3T/(8ab²)·[1 + 0.6095 r + 0.8865 r² − 1.8023 r³ +
/// 0.9100 r⁴] with half-sides a ≥ b, r = b/a. Short side: the long-side value times Timoshenko &
/// Goodier's ratio (1.000 at a square falling to 0.742 for thin strips), interpolated.
void TorsionShearPerNm(double long_m, double short_m, double* long_side, double* short_side) {
  const double a = 0.5 * long_m;
  const double b = 0.5 * short_m;
  const double r = b / a;
  *long_side = 3.0 / (8.0 * a * b * b) *
               (1 + 0.6095 * r + 0.8865 * r * r - 1.8023 * r * r * r + 0.9100 * r * r * r * r);
  static constexpr double kAspect[] = {1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 10.0};
  static constexpr double kRatio[] = {1.000, 0.859, 0.795, 0.753, 0.745, 0.743, 0.742};
  const double q = long_m / short_m;
  double ratio = kRatio[6];
  for (int i = 0; i < 6; ++i) {
    if (q <= kAspect[i + 1]) {
      const double f = (q - kAspect[i]) / (kAspect[i + 1] - kAspect[i]);
      ratio = kRatio[i] + f * (kRatio[i + 1] - kRatio[i]);
      break;
    }
  }
  *short_side = ratio * *long_side;
}

}  // namespace

FlexureBody::FlexureBody(const FlexureGeometry& g) : g_(g) {
  if (g.beam_count != 3 && g.beam_count != 4) {
    throw std::invalid_argument("flexure body: beam_count must be 3 or 4, not " +
                                std::to_string(g.beam_count));
  }
  if (!Finite(g.hub_radius_m) || g.hub_radius_m < 0 || !Finite(g.rim_radius_m) ||
      g.rim_radius_m <= g.hub_radius_m) {
    throw std::invalid_argument("flexure body: need 0 <= hub_radius_m < rim_radius_m");
  }
  if (!Finite(g.first_beam_deg)) throw std::invalid_argument("flexure body: first_beam_deg");
  for (double c : g.rim_compliance) {
    if (!Finite(c) || c < 0) {
      throw std::invalid_argument("flexure body: rim compliances must be finite and >= 0");
    }
  }
  section_ = RectangularSection(g.e_pa, g.poisson, g.beam_width_m, g.beam_height_m);
  length_m_ = g.rim_radius_m - g.hub_radius_m;
  const Mat12 kl_member = g.shear_deformable ? TimoshenkoElementStiffness(section_, length_m_)
                                             : FrameElementStiffness(section_, length_m_);
  const EndCompliance root = g.elastic_roots
                                 ? BuiltInRootCompliance(g.e_pa, g.beam_width_m, g.beam_height_m)
                                 : EndCompliance{};
  const Mat12 kl = WithEndCompliance(kl_member, length_m_, root, root);
  const Mat6 k11 = kl.topLeftCorner<6, 6>();
  const Mat6 k12 = kl.topRightCorner<6, 6>();
  const Mat6 k22 = kl.bottomRightCorner<6, 6>();

  // Condense the rim node: its free DOFs carry a spring to ground (1/compliance), its rigid DOFs
  // are held at zero. rim_map gives the rim node's local displacement per hub-node displacement.
  Mat6 rim_map = Mat6::Zero();
  {
    std::vector<int> free;
    for (int i = 0; i < 6; ++i) {
      if (g.rim_compliance[static_cast<std::size_t>(i)] > 0) free.push_back(i);
    }
    const int nf = static_cast<int>(free.size());
    if (nf > 0) {
      Eigen::MatrixXd kff(nf, nf);
      Eigen::MatrixXd kf1(nf, 6);
      for (int a = 0; a < nf; ++a) {
        for (int b = 0; b < nf; ++b) kff(a, b) = k22(free[a], free[b]);
        kff(a, a) += 1.0 / g.rim_compliance[static_cast<std::size_t>(free[a])];
        for (int c = 0; c < 6; ++c) kf1(a, c) = k12(c, free[a]);  // K21 = K12ᵀ
      }
      const Eigen::MatrixXd uf = -kff.ldlt().solve(kf1);
      for (int a = 0; a < nf; ++a) rim_map.row(free[a]) = uf.row(a);
    }
  }
  const Mat6 kc_local = k11 + k12 * rim_map;  // condensed stiffness at the hub end, beam-local

  // Each beam's hub node follows the rigid hub: [u1; θ1] = T·[u_hub; θ_hub]; local = Rb·global.
  k_hub_.setZero();
  std::vector<Eigen::Matrix<double, 6, 6>> to_local(static_cast<std::size_t>(g.beam_count));
  for (int i = 0; i < g.beam_count; ++i) {
    const double th = (g.first_beam_deg + 360.0 * i / g.beam_count) * std::numbers::pi / 180.0;
    Eigen::Matrix3d r;  // rows: local x, y, z in the sensor frame
    r << std::cos(th), std::sin(th), 0, -std::sin(th), std::cos(th), 0, 0, 0, 1;
    const Eigen::Vector3d p1 = g.hub_radius_m * r.row(0).transpose();
    Mat6 t = Mat6::Identity();
    t.topRightCorner<3, 3>() = -Skew(p1);
    Mat6 rb = Mat6::Zero();
    rb.topLeftCorner<3, 3>() = r;
    rb.bottomRightCorner<3, 3>() = r;
    const Mat6 a = rb * t;  // hub displacement → local hub-node displacement
    to_local[static_cast<std::size_t>(i)] = a;
    k_hub_ += a.transpose() * kc_local * a;
  }
  compliance_hub_ = k_hub_.inverse();
  if (!compliance_hub_.allFinite()) throw std::invalid_argument("flexure body: singular stiffness");

  end_force_map_.resize(static_cast<std::size_t>(g.beam_count));
  for (int i = 0; i < g.beam_count; ++i) {
    Eigen::Matrix<double, 12, 6> u_local;  // both nodes' local displacements per unit wrench
    const Mat6 u1 = to_local[static_cast<std::size_t>(i)] * compliance_hub_;
    u_local.topRows<6>() = u1;
    u_local.bottomRows<6>() = rim_map * u1;
    end_force_map_[static_cast<std::size_t>(i)] = kl * u_local;
  }
}

Eigen::Matrix<double, 6, 1> FlexureBody::HubDisplacement(const Wrench& w) const {
  return compliance_hub_ * w;
}

void FlexureBody::CheckSite(int beam, double position_m) const {
  if (beam < 0 || beam >= g_.beam_count) {
    throw std::invalid_argument("flexure body: beam index " + std::to_string(beam) +
                                " out of range");
  }
  if (!Finite(position_m) || position_m < 0 || position_m > length_m_ * (1 + 1e-12)) {
    throw std::invalid_argument("flexure body: position " + std::to_string(position_m) +
                                " m is not on the beam (length " + std::to_string(length_m_) +
                                " m)");
  }
}

Eigen::Matrix<double, 12, 1> FlexureBody::BeamEndForces(int beam, const Wrench& w) const {
  CheckSite(beam, 0);
  return end_force_map_[static_cast<std::size_t>(beam)] * w;
}

Eigen::Matrix<double, 6, 6> FlexureBody::SectionMatrix(int beam, double s) const {
  CheckSite(beam, s);
  // Free body of [0, s]: node-1 end forces f1, m1 plus the section resultant balance to zero.
  const auto& e = end_force_map_[static_cast<std::size_t>(beam)];
  Mat6 m;
  m.row(0) = -e.row(0);                 // N
  m.row(1) = -e.row(1);                 // Vy
  m.row(2) = -e.row(2);                 // Vz
  m.row(3) = -e.row(3);                 // T
  m.row(4) = -e.row(4) - s * e.row(2);  // My
  m.row(5) = -e.row(5) + s * e.row(1);  // Mz
  return m;
}

SectionForces FlexureBody::SectionAt(int beam, double position_m, const Wrench& w) const {
  const Eigen::Matrix<double, 6, 1> r = SectionMatrix(beam, position_m) * w;
  return SectionForces{r(0), r(1), r(2), r(3), r(4), r(5)};
}

Eigen::Matrix<double, 2, 6> FlexureBody::FaceStrainMatrix(int beam, double s, BeamFace face,
                                                          double offset_m, double angle_deg) const {
  const Mat6 sec = SectionMatrix(beam, s);
  const double b = g_.beam_width_m;
  const double h = g_.beam_height_m;
  const bool top_bottom = face == BeamFace::kTop || face == BeamFace::kBottom;
  const double face_width = top_bottom ? b : h;
  if (!Finite(offset_m) || std::abs(offset_m) > 0.5 * face_width * (1 + 1e-12)) {
    throw std::invalid_argument("flexure body: gauge offset " + std::to_string(offset_m) +
                                " m lies off the face");
  }
  if (!Finite(angle_deg)) throw std::invalid_argument("flexure body: gauge angle is not finite");
  double y = 0;
  double z = 0;
  double sign = 1;  // torsional shear direction on this face for positive T (τ_xs)
  switch (face) {
    case BeamFace::kTop:
      y = offset_m, z = 0.5 * h, sign = -1;
      break;
    case BeamFace::kBottom:
      y = offset_m, z = -0.5 * h, sign = 1;
      break;
    case BeamFace::kPlusY:
      y = 0.5 * b, z = offset_m, sign = 1;
      break;
    case BeamFace::kMinusY:
      y = -0.5 * b, z = offset_m, sign = -1;
      break;
  }
  const BeamSection& sc = section_;
  // Normal stress per unit wrench.
  const Eigen::Matrix<double, 1, 6> sigma =
      sec.row(0) / sc.area_m2 + sec.row(4) * (z / sc.iy_m4) - sec.row(5) * (y / sc.iz_m4);
  // In-plane shear: transverse shear (elementary parabolic distribution) plus torsion (face
  // mid-line value from TorsionShearPerNm, tapered parabolically to zero at the corners).
  double t_long = 0;
  double t_short = 0;
  TorsionShearPerNm(std::max(b, h), std::min(b, h), &t_long, &t_short);
  const bool face_is_long = top_bottom ? (b >= h) : (h > b);
  const double u = 2.0 * offset_m / face_width;
  const double taper = 1.0 - u * u;
  const double t_face = (face_is_long ? t_long : t_short) * taper;
  const Eigen::Matrix<double, 1, 6> shear_force = top_bottom ? sec.row(1) : sec.row(2);
  const Eigen::Matrix<double, 1, 6> tau =
      shear_force * (1.5 / sc.area_m2 * taper) + sec.row(3) * (sign * t_face);

  const double e = sc.e_pa;
  const double nu = e / (2.0 * sc.g_pa) - 1.0;
  const Eigen::Matrix<double, 1, 6> exx = sigma / e;
  const Eigen::Matrix<double, 1, 6> ess = -nu * sigma / e;
  const Eigen::Matrix<double, 1, 6> gxs = tau / sc.g_pa;
  const double phi = angle_deg * std::numbers::pi / 180.0;
  const double c = std::cos(phi);
  const double sn = std::sin(phi);
  Eigen::Matrix<double, 2, 6> out;
  out.row(0) = exx * (c * c) + ess * (sn * sn) + gxs * (sn * c);
  out.row(1) = exx * (sn * sn) + ess * (c * c) - gxs * (sn * c);
  return out;
}

Eigen::Matrix<double, 2, 6> FlexureBody::StrainMatrix(const GaugeSite& site) const {
  return FaceStrainMatrix(site.beam, site.position_m, site.face, site.offset_m, site.angle_deg);
}

GaugeStrain FlexureBody::StrainAt(const GaugeSite& site, const Wrench& w) const {
  const Eigen::Vector2d e = StrainMatrix(site) * w;
  return GaugeStrain{e(0), e(1)};
}

double FlexureBody::MaxSurfaceStrain(
    const std::function<double(const Eigen::Matrix<double, 1, 6>&)>& worst_of) const {
  double worst = 0;
  const double hb = 0.5 * g_.beam_width_m;
  const double hh = 0.5 * g_.beam_height_m;
  for (int i = 0; i < g_.beam_count; ++i) {
    for (double s : {0.0, length_m_}) {
      const Mat6 sec = SectionMatrix(i, s);
      for (double y : {-hb, hb}) {
        for (double z : {-hh, hh}) {
          const Eigen::Matrix<double, 1, 6> sigma = sec.row(0) / section_.area_m2 +
                                                    sec.row(4) * (z / section_.iy_m4) -
                                                    sec.row(5) * (y / section_.iz_m4);
          worst = std::max(worst, worst_of(sigma / section_.e_pa));
        }
      }
    }
  }
  return worst;
}

}  // namespace ftstack::sim
