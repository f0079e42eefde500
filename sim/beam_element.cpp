#include "sim/beam_element.hpp"

#include <cmath>
#include <stdexcept>

namespace ftstack::sim {
namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0; }

/// 12-DOF stiffness; with `shear` each bending plane carries Φ = 12EI/(κGAL²), else Φ = 0.
Eigen::Matrix<double, 12, 12> ElementStiffness(const BeamSection& s, double length_m, bool shear) {
  if (!Positive(length_m)) throw std::invalid_argument("beam length must be positive and finite");
  if (shear && !(Positive(s.shear_factor) && Positive(s.g_pa))) {
    throw std::invalid_argument("beam section: shear factor and G must be positive and finite");
  }
  const double l = length_m;
  const double l2 = l * l;
  const double l3 = l2 * l;
  const double ga = shear ? s.shear_factor * s.g_pa * s.area_m2 : 0.0;
  auto phi = [&](double ei) { return shear ? 12.0 * ei / (ga * l2) : 0.0; };
  Eigen::Matrix<double, 12, 12> k = Eigen::Matrix<double, 12, 12>::Zero();
  auto set = [&k](int i, int j, double v) {
    k(i, j) = v;
    k(j, i) = v;
  };
  // Axial.
  const double ea = s.e_pa * s.area_m2 / l;
  set(0, 0, ea);
  set(6, 6, ea);
  set(0, 6, -ea);
  // Torsion.
  const double gj = s.g_pa * s.j_m4 / l;
  set(3, 3, gj);
  set(9, 9, gj);
  set(3, 9, -gj);
  // Bending in the x–y plane (v, rz): EIz.
  const double ez = s.e_pa * s.iz_m4;
  const double pz = phi(ez);
  const double cz = ez / (1 + pz);
  set(1, 1, 12 * cz / l3);
  set(7, 7, 12 * cz / l3);
  set(1, 7, -12 * cz / l3);
  set(1, 5, 6 * cz / l2);
  set(1, 11, 6 * cz / l2);
  set(7, 5, -6 * cz / l2);
  set(7, 11, -6 * cz / l2);
  set(5, 5, (4 + pz) * cz / l);
  set(11, 11, (4 + pz) * cz / l);
  set(5, 11, (2 - pz) * cz / l);
  // Bending in the x–z plane (w, ry): EIy; a positive ry turns +x toward −z, hence the signs.
  const double ey = s.e_pa * s.iy_m4;
  const double py = phi(ey);
  const double cy = ey / (1 + py);
  set(2, 2, 12 * cy / l3);
  set(8, 8, 12 * cy / l3);
  set(2, 8, -12 * cy / l3);
  set(2, 4, -6 * cy / l2);
  set(2, 10, -6 * cy / l2);
  set(8, 4, 6 * cy / l2);
  set(8, 10, 6 * cy / l2);
  set(4, 4, (4 + py) * cy / l);
  set(10, 10, (4 + py) * cy / l);
  set(4, 10, (2 - py) * cy / l);
  return k;
}

}  // namespace

double RectangleTorsionConstant(double long_m, double short_m) {
  if (!Positive(long_m) || !Positive(short_m)) {
    throw std::invalid_argument("rectangle sides must be positive and finite");
  }
  const double a = std::max(long_m, short_m);
  const double b = std::min(long_m, short_m);
  const double r = b / a;
  return a * b * b * b * (1.0 / 3.0 - 0.21 * r * (1.0 - r * r * r * r / 12.0));
}

BeamSection RectangularSection(double e_pa, double poisson, double width_m, double height_m) {
  if (!Positive(e_pa) || !Positive(width_m) || !Positive(height_m)) {
    throw std::invalid_argument("beam section: E, width and height must be positive and finite");
  }
  if (!std::isfinite(poisson) || poisson <= -1.0 || poisson >= 0.5) {
    throw std::invalid_argument("beam section: Poisson's ratio must lie in (-1, 0.5)");
  }
  BeamSection s;
  s.e_pa = e_pa;
  s.g_pa = e_pa / (2.0 * (1.0 + poisson));
  s.area_m2 = width_m * height_m;
  s.iy_m4 = width_m * height_m * height_m * height_m / 12.0;
  s.iz_m4 = height_m * width_m * width_m * width_m / 12.0;
  s.j_m4 = RectangleTorsionConstant(width_m, height_m);
  return s;
}

Eigen::Matrix<double, 12, 12> FrameElementStiffness(const BeamSection& s, double length_m) {
  return ElementStiffness(s, length_m, false);
}

Eigen::Matrix<double, 12, 12> TimoshenkoElementStiffness(const BeamSection& s, double length_m) {
  return ElementStiffness(s, length_m, true);
}

}  // namespace ftstack::sim
