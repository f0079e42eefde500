// Design figures of a sensor body: capacities, noise-limited resolution, stiffness, modes, margins.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "sim/design/frame.hpp"

namespace ftstack::sim::design {

using Vec6 = Eigen::Matrix<double, 6, 1>;

/// Flexure material. Stresses in Pa; allowable_gauge_strain is the strain a foil gauge and its
/// bond survive for the rated number of cycles (the measuring range of the gauges).
struct Material {
  std::string name;
  double e_pa = 0, poisson = 0.3;
  double yield_pa = 0;
  double fatigue_pa = 0;  ///< fully reversed endurance limit (rated load may cycle ±)
  double allowable_gauge_strain = 1.0e-3;
};

/// 17-4 PH H900 stainless (E 197 GPa, yield 1170 MPa, endurance 620 MPa — handbook values).
[[nodiscard]] Material Steel174Ph();
/// 7075-T6 aluminium (E 71.7 GPa, yield 503 MPa, endurance 159 MPa at 5·10⁸ cycles).
[[nodiscard]] Material Aluminium7075();

/// A line of the body drawn in the report (global end points, m) with its surface strain per
/// unit wrench at `stations` evenly spaced points from a to b (largest |strain| over the faces).
struct SketchSegment {
  Eigen::Vector3d a, b;
  std::vector<std::array<Row6, 4>> stations;  ///< 4 face rows per station
};

/// A compressed member: axial force (N, tension +) per unit wrench and its critical load.
struct BucklingCheck {
  Row6 axial_n;
  double critical_n = 0;
};

/// Where a gauge grid sits on the body: its centre (m), grid direction and outward surface
/// normal (unit vectors, sensor frame), and a name such as "z force, + leaf, top".
struct GaugeGrid {
  std::string name;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// A prismatic member as a solid: end a on rigid body body_a, end b on body_b (0 ground, 1 the
/// loaded platform, 2… intermediate stages), section width_m along y_axis × height_m along
/// z_axis (unit vectors normal to the member). What a solid FE check meshes.
struct SolidMember {
  Eigen::Vector3d a_m = Eigen::Vector3d::Zero(), b_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d z_axis = Eigen::Vector3d::UnitZ();
  double width_m = 0, height_m = 0;
  int body_a = 0, body_b = 0;
  /// End b held to body_b through springs (member-local ux uy uz in m/N, rx ry rz in rad/(N·m));
  /// 0: rigid. The "floating" radial release of hub-spoke beams at the rim.
  std::array<double, 6> end_b_compliance{};
};

/// Everything the evaluation needs, produced by a family (linear models, per unit wrench).
struct DesignModel {
  std::string family, name;
  std::map<std::string, double> parameters;  ///< geometry for tables (m, or as named)
  Material material;
  Mat6 stiffness = Mat6::Zero();
  Eigen::MatrixXd gauge_strain;      ///< G × 6 grid strain
  std::vector<GaugeGrid> gauges;     ///< G, the rows of gauge_strain
  std::vector<SolidMember> members;  ///< the body under the model's idealisations
  int body_count = 2;                ///< rigid bodies, ground and platform included
  Eigen::MatrixXd sensitivity_mvv;   ///< N × 6 bridge output, mV/V per N or N·m
  Eigen::MatrixXd stress_normal;     ///< P × 6 normal stress (Pa) at checked section corners
  Eigen::MatrixXd stress_shear;      ///< Q × 6 largest torsional shear (Pa) at checked sections
  std::vector<BucklingCheck> buckling;
  std::vector<SketchSegment> sketch;
  double bridge_noise_mvv = 0;  ///< per bridge, RMS over the converter's bandwidth
  double native_bandwidth_hz = 0;
  /// "" when every member is a slender beam (SlenderBeamViolation), else the first violation:
  /// the beam figures are then not to be trusted alone and the design is not ranked.
  std::string beam_validity;
};

/// Options of an evaluation; every assumption is a number here.
struct DesignOptions {
  double safety_factor = 1.5;     ///< on yield (and on buckling) for the rated capacity
  double bandwidth_hz = 0;        ///< 0: the converter's native bandwidth
  double tool_mass_kg = 1.0;      ///< rigid tool on the platform
  double tool_com_z_m = 0.05;     ///< its centre of mass on the sensor axis
  double tool_gyration_m = 0.05;  ///< radius of gyration about its centre of mass
};

/// Which limit sets a capacity.
enum class Limit : std::uint8_t { kGaugeStrain, kYield, kFatigue, kBuckling };
[[nodiscard]] std::string ToString(Limit l);

struct DesignFigures {
  Vec6 capacity = Vec6::Zero();  ///< per axis alone, N and N·m
  std::array<Limit, 6> binding{};
  double combined_scale = 1;       ///< capacity × this meets the combined-load rule (≤ 1)
  Vec6 resolution = Vec6::Zero();  ///< 1σ noise-limited, at bandwidth_hz
  double bandwidth_hz = 0;
  Mat6 stiffness = Mat6::Zero();
  Vec6 natural_hz = Vec6::Zero();  ///< ascending
  double overload_margin = 0;      ///< yield stress / largest stress at rated (combined) load
  double condition_number = 0;     ///< of sensitivity × diag(capacity), 2-norm
  double force_range_n = 0;        ///< max(Fx, Fy, Fz capacity)
  double tilt_capacity_nm = 0;     ///< min(Mx, My capacity)
  double force_resolution_n = 0;   ///< max(Fx, Fy, Fz resolution)
};

/// Worst-case of a linear quantity c·w over a load set.
class LoadSet {
 public:
  virtual ~LoadSet() = default;
  [[nodiscard]] virtual double Max(const Row6& c) const = 0;
};

/// Every load with |Fxy| ≤ fxy, |Fz| ≤ fz, |Mxy| ≤ mxy, |Mz| ≤ mz acting together in any direction.
class EnvelopeLoads final : public LoadSet {
 public:
  EnvelopeLoads(double fxy, double fz, double mxy, double mz) : r_{fxy, fz, mxy, mz} {}
  [[nodiscard]] double Max(const Row6& c) const override;
  [[nodiscard]] const std::array<double, 4>& ranges() const { return r_; }

 private:
  std::array<double, 4> r_;
};

/// A list of wrenches; each also counts with its sign reversed.
class CaseLoads final : public LoadSet {
 public:
  explicit CaseLoads(std::vector<Vec6> cases) : cases_(std::move(cases)) {}
  [[nodiscard]] double Max(const Row6& c) const override;

 private:
  std::vector<Vec6> cases_;
};

/// Largest von Mises stress (Pa) over a load set: √(σ² + 3τ²) with σ and τ each at their own
/// worst (conservative: the two maxima may sit at different points or loads).
[[nodiscard]] double WorstStress(const DesignModel& m, const LoadSet& loads);
/// Largest |grid strain| at a gauge; largest compressive force / critical load of a member.
[[nodiscard]] double WorstGaugeStrain(const DesignModel& m, const LoadSet& loads);
[[nodiscard]] double WorstBucklingRatio(const DesignModel& m, const LoadSet& loads);

[[nodiscard]] DesignFigures Evaluate(const DesignModel& m, const DesignOptions& o);

/// Natural frequencies (Hz, ascending) of a rigid tool on stiffness k: K v = ω² M v.
[[nodiscard]] Vec6 NaturalFrequenciesHz(const Mat6& k, double mass_kg, double com_z_m,
                                        double gyration_m);

}  // namespace ftstack::sim::design
