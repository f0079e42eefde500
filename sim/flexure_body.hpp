// Hub-and-rim flexure body of 3 or 4 radial Euler–Bernoulli beams: wrench → hub motion → strains.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/beam_element.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::sim {

/// Sensor frame: origin at the hub centre, z the sensor axis, beam i along the radial direction at
/// first_beam_deg + i·360°/beam_count from +x in the x–y plane. Beam-local frame: x radial
/// (hub → rim), y tangential (counter-clockwise), z = sensor z. The section is beam_width_m along
/// local y and beam_height_m along local z. The hub is rigid; the wrench acts at the hub centre.
struct FlexureGeometry {
  int beam_count = 3;         ///< 3 (three-beam) or 4 (Maltese cross)
  double hub_radius_m = 0;    ///< beam roots (node 1) lie at this radius
  double rim_radius_m = 0;    ///< beam ends (node 2) lie at this radius
  double beam_width_m = 0;    ///< along local y (tangential)
  double beam_height_m = 0;   ///< along local z (axial direction of the sensor)
  double first_beam_deg = 0;  ///< angle of beam 0 from +x, degrees
  double e_pa = 0;            ///< Young's modulus, Pa
  double poisson = 0.3;       ///< Poisson's ratio
  /// Compliance of each beam's attachment to the rim, beam-local at the rim end: ux uy uz in m/N,
  /// rx ry rz in rad/(N·m). 0 = rigid (the default: rim fixed). A radial release (ux > 0) models
  /// the thin "floating" links that let the beams slide radially in classic designs.
  std::array<double, 6> rim_compliance{};
  /// Timoshenko beams (shear factor 5/6) instead of Euler–Bernoulli; off for the sensor models
  /// (their calibration does not depend on it), on for the design explorer's stubby beams.
  bool shear_deformable = false;
  /// The beams' roots in an elastic hub and rim: each beam end rotates in its support by
  /// O'Donnell's built-in-root compliance (sim/beam_root.hpp) in series with the beam. Off: the
  /// roots are ideal clamps (hub and rim rigid).
  bool elastic_roots = false;
};

/// Faces of a beam: top = local +z, bottom = −z, plus_y = +y side, minus_y = −y side.
/// Every face has the in-plane axes (x, s): s = +y on top/bottom and s = +z on the sides.
enum class BeamFace : std::uint8_t { kTop, kBottom, kPlusY, kMinusY };

/// Where a gauge sits and how it is turned.
struct GaugeSite {
  int beam = 0;
  double position_m = 0;  ///< distance from the hub end of the beam along its axis, 0 … length
  BeamFace face = BeamFace::kTop;
  double offset_m = 0;   ///< along the face's s axis from the face centre line
  double angle_deg = 0;  ///< grid direction measured from local x toward s
};

/// Internal force resultants at a section (on the face whose normal is +x local): N, V in N;
/// T (torque about x), My, Mz in N·m. Stress: σ = N/A + My·z/Iy − Mz·y/Iz.
struct SectionForces {
  double n = 0, vy = 0, vz = 0, t = 0, my = 0, mz = 0;
};

/// Strain along the gauge grid (axial) and perpendicular to it in the face plane (transverse).
struct GaugeStrain {
  double axial = 0;
  double transverse = 0;
};

/// The solved linear body. Construction validates the geometry (std::invalid_argument), assembles
/// the beams and factorises the hub stiffness; every query afterwards is a matrix product.
class FlexureBody {
 public:
  explicit FlexureBody(const FlexureGeometry& g);

  [[nodiscard]] const FlexureGeometry& geometry() const { return g_; }
  [[nodiscard]] const BeamSection& section() const { return section_; }
  [[nodiscard]] double beam_length_m() const { return length_m_; }
  [[nodiscard]] int beam_count() const { return g_.beam_count; }

  /// 6×6 stiffness of the hub: wrench = K·[ux uy uz (m), rx ry rz (rad)].
  [[nodiscard]] const Eigen::Matrix<double, 6, 6>& Stiffness() const { return k_hub_; }
  /// Hub displacement (m, rad) under wrench w.
  [[nodiscard]] Eigen::Matrix<double, 6, 1> HubDisplacement(const Wrench& w) const;
  /// Forces of beam `beam` on its element ends, beam-local, 12 values (node 1 then node 2), per w.
  [[nodiscard]] Eigen::Matrix<double, 12, 1> BeamEndForces(int beam, const Wrench& w) const;
  /// Section resultants at position_m from the hub end of `beam`.
  [[nodiscard]] SectionForces SectionAt(int beam, double position_m, const Wrench& w) const;
  /// Linear map wrench → (axial, transverse) strain of a gauge at `site` (2×6).
  [[nodiscard]] Eigen::Matrix<double, 2, 6> StrainMatrix(const GaugeSite& site) const;
  /// Strain of a gauge at `site` under w.
  [[nodiscard]] GaugeStrain StrainAt(const GaugeSite& site, const Wrench& w) const;
  /// Largest |normal strain| at any section corner of any beam end (where bending peaks), each
  /// corner's linear map wrench → strain (1×6) reduced to a number by `worst` (e.g. the maximum
  /// over a load envelope).
  [[nodiscard]] double MaxSurfaceStrain(
      const std::function<double(const Eigen::Matrix<double, 1, 6>&)>& worst) const;

 private:
  [[nodiscard]] Eigen::Matrix<double, 6, 6> SectionMatrix(int beam, double position_m) const;
  [[nodiscard]] Eigen::Matrix<double, 2, 6> FaceStrainMatrix(int beam, double position_m,
                                                             BeamFace face, double offset_m,
                                                             double angle_deg) const;
  void CheckSite(int beam, double position_m) const;

  FlexureGeometry g_;
  BeamSection section_;
  double length_m_ = 0;
  Eigen::Matrix<double, 6, 6> k_hub_;
  Eigen::Matrix<double, 6, 6> compliance_hub_;
  /// Per beam: local end forces (12) per unit hub wrench component (12×6).
  std::vector<Eigen::Matrix<double, 12, 6>> end_force_map_;
};

}  // namespace ftstack::sim
