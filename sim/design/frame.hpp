// Rigid bodies joined by Timoshenko (or Euler–Bernoulli) beams: assembly, one factorisation,
// per-unit-wrench maps, and the check that every member is a beam at all.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "sim/beam_element.hpp"
#include "sim/beam_root.hpp"

namespace ftstack::sim::design {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Row6 = Eigen::Matrix<double, 1, 6>;

/// Body 0 is the ground (fixed), body 1 the loaded platform (the wrench acts at the global origin),
/// bodies 2 … the intermediate rigid stages. A free node has its own 6 DOFs.
inline constexpr int kGround = 0;
inline constexpr int kPlatform = 1;

/// Where an element end sits: on rigid body `body` at `point_m`, or on free node `node` (body < 0).
struct Anchor {
  int body = -1;
  int node = -1;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< used when body >= 0
};

/// A prismatic beam of rectangular section width_m (local y) × height_m (local z).
/// Local x runs from end a to end b; local z is `z_hint` made normal to x; local y = z × x.
struct FrameElement {
  Anchor a, b;
  double width_m = 0, height_m = 0;
  Eigen::Vector3d z_hint = Eigen::Vector3d::UnitZ();
  std::string label;  ///< e.g. "z-stage A upper leaf"
  /// Effective buckling length of the member this element belongs to (0: no buckling check).
  double buckling_length_m = 0;
  /// Length of the member this element is part of (for the plate factor); 0: the element's own.
  double member_length_m = 0;
  /// Compliance of the joints at end a and end b (local axes, in series with the element; e.g.
  /// BuiltInRootCompliance for a root in an elastic block). Zero: ideal clamps.
  EndCompliance joint_a{}, joint_b{};
};

/// A linear spring from free node `node` to the ground, global 6×6 stiffness.
struct NodeSpring {
  int node = 0;
  Mat6 k = Mat6::Zero();
};

struct FrameModel {
  int body_count = 2;  ///< ground + platform + intermediate stages
  std::vector<Eigen::Vector3d> nodes_m;
  std::vector<FrameElement> elements;
  std::vector<NodeSpring> springs;
  double e_pa = 0, poisson = 0.3;
  /// Timoshenko elements (shear factor 5/6) and the plate factor: a member wider than it is long
  /// bends through its thickness with E/(1 − ν²) (anticlastic curvature held flat). false: the
  /// classic Euler–Bernoulli beam with E.
  bool shear_deformable = true;
};

/// Plate factor of a member: 1/(1 − ν²) when its larger section side exceeds its length, else 1.
[[nodiscard]] double PlateFactor(double length_m, double width_m, double height_m, double poisson);

/// Whether a prismatic member is in the range where beam theory (with the shear correction)
/// holds: L ≥ 2·h for the larger section side h, except for a leaf (b ≥ 5·t), which needs
/// L ≥ 2·t through its thickness and L ≥ 0.5·b in its plane (there the shear correction carries
/// a deep beam). Returns "" when it is, else what fails, e.g. "L/h = 1.20 < 2".
[[nodiscard]] std::string SlenderBeamViolation(double length_m, double width_m, double height_m);

/// Section resultants per unit wrench (rows N, Vy, Vz, T, My, Mz), units N and N·m per N or N·m.
using SectionRows = Mat6;

/// The solved frame. Construction validates, assembles, factorises once (LDLT) and solves the six
/// unit platform wrenches; afterwards every query is a small matrix product.
class FrameSolution {
 public:
  explicit FrameSolution(FrameModel model);

  [[nodiscard]] const FrameModel& model() const { return m_; }
  /// Platform stiffness at the origin: wrench = K·[u (m); θ (rad)].
  [[nodiscard]] const Mat6& Stiffness() const { return k_platform_; }
  [[nodiscard]] const Mat6& Compliance() const { return c_platform_; }
  [[nodiscard]] double Length(int element) const;
  [[nodiscard]] const BeamSection& Section(int element) const;
  /// Resultants at distance s_m from end a of `element` (free body of [0, s]).
  [[nodiscard]] SectionRows SectionAt(int element, double s_m) const;
  /// Normal strain (grid along the beam) at local section point (y_m, z_m), per unit wrench.
  [[nodiscard]] Row6 AxialStrain(int element, double s_m, double y_m, double z_m) const;
  /// Normal stress (Pa) at the same point, per unit wrench.
  [[nodiscard]] Row6 NormalStress(int element, double s_m, double y_m, double z_m) const;
  /// Global position of end a / b.
  [[nodiscard]] Eigen::Vector3d EndPoint(int element, bool end_b) const;
  /// Displacement of every DOF per unit wrench (rows: 6 per moving body, then 6 per free node).
  [[nodiscard]] const Eigen::MatrixXd& UnitDisplacements() const { return u_; }

 private:
  struct ElementData {
    double length = 0;
    BeamSection section;  ///< iy_m4 already divided by (1 − ν²) for a plate
    double plate = 1;     ///< plate factor of bending through the height
    Eigen::Matrix<double, 12, 12> k_local;
    Eigen::Matrix<double, 12, 6> end_forces;  ///< local end forces per unit wrench
  };
  [[nodiscard]] int DofOf(const Anchor& a) const;
  [[nodiscard]] Mat6 EndMap(const Anchor& a, const Eigen::Matrix3d& r) const;

  FrameModel m_;
  std::vector<ElementData> el_;
  Eigen::MatrixXd u_;
  Mat6 k_platform_, c_platform_;
};

/// Rotation whose rows are the local x, y, z axes of a beam from p to q with z near z_hint.
[[nodiscard]] Eigen::Matrix3d ElementRotation(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                              const Eigen::Vector3d& z_hint);

/// Largest torsional shear stress of a rectangle per N·m (Roark, Table 10.7 case 4, long side).
[[nodiscard]] double RectangleTorsionShearPerNm(double side1_m, double side2_m);

}  // namespace ftstack::sim::design
