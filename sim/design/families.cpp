#include "sim/design/families.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace ftstack::sim::design {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::MatrixXd Stack(const std::vector<Row6>& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), 6);
  for (std::size_t i = 0; i < rows.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = rows[i];
  return m;
}

/// Centre, grid direction and normal of a gauge on a FlexureBody beam (frame of the body).
GaugeGrid GridOf(const FlexureGeometry& g, const GaugeSite& site) {
  const double th = (g.first_beam_deg + 360.0 * site.beam / g.beam_count) * kPi / 180.0;
  const Eigen::Vector3d x(std::cos(th), std::sin(th), 0), y(-std::sin(th), std::cos(th), 0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d n = z, s_axis = y;
  double half = 0;
  static constexpr const char* kFace[] = {"top", "bottom", "+y side", "-y side"};
  switch (site.face) {
    case BeamFace::kTop:
      n = z, s_axis = y, half = 0.5 * g.beam_height_m;
      break;
    case BeamFace::kBottom:
      n = -z, s_axis = y, half = 0.5 * g.beam_height_m;
      break;
    case BeamFace::kPlusY:
      n = y, s_axis = z, half = 0.5 * g.beam_width_m;
      break;
    case BeamFace::kMinusY:
      n = -y, s_axis = z, half = 0.5 * g.beam_width_m;
      break;
  }
  GaugeGrid grid;
  grid.point_m = (g.hub_radius_m + site.position_m) * x + half * n + site.offset_m * s_axis;
  const double a = site.angle_deg * kPi / 180.0;
  grid.direction = std::cos(a) * x + std::sin(a) * s_axis;
  grid.normal = n;
  grid.name = "beam " + std::to_string(site.beam) + ", " + kFace[static_cast<int>(site.face)] +
              ", " + std::to_string(static_cast<int>(std::lround(site.angle_deg))) + " deg";
  return grid;
}

}  // namespace

double ReadoutNoiseMvv(const Readout& r) {
  return MakeAdcOperatingPoint(r.adc).params.noise_rms_mvv;
}

DesignModel FromPhysicalSensor(const PhysicalSensorModel& s, const Material& mat,
                               double bridge_noise_mvv, double rate_hz) {
  const FlexureBody& body = s.body();
  const FlexureGeometry& g = body.geometry();
  DesignModel m;
  m.family = "hub-spoke";
  m.name = s.name();
  m.material = mat;
  m.parameters = {
      {"beams", g.beam_count},          {"rim_compliance_radial_m_per_n", g.rim_compliance[0]},
      {"hub_radius_m", g.hub_radius_m}, {"rim_radius_m", g.rim_radius_m},
      {"beam_width_m", g.beam_width_m}, {"beam_height_m", g.beam_height_m}};
  if (g.elastic_roots)
    m.parameters["elastic_roots"] = 1;  // named only when on: specs stay as they were
  m.stiffness = body.Stiffness();
  std::vector<Row6> gauges;
  for (const GaugeSite& site : s.spec().gauges) {
    gauges.push_back(body.StrainMatrix(site).row(0));
    m.gauges.push_back(GridOf(g, site));
  }
  m.beam_validity = SlenderBeamViolation(body.beam_length_m(), g.beam_width_m, g.beam_height_m);
  m.gauge_strain = Stack(gauges);
  m.sensitivity_mvv = s.Report().sensitivity_mvv;
  std::vector<Row6> normal;
  (void)body.MaxSurfaceStrain([&](const Row6& c) {
    normal.push_back(c * g.e_pa);
    return 0.0;
  });
  m.stress_normal = Stack(normal);
  const BeamSection& sc = body.section();
  const double tau = RectangleTorsionShearPerNm(g.beam_width_m, g.beam_height_m);
  const double i_min = std::min(sc.iy_m4, sc.iz_m4);
  const double length = body.beam_length_m();
  std::vector<Row6> shear;
  for (int b = 0; b < g.beam_count; ++b) {
    Eigen::Matrix<double, 12, 6> ends;
    for (int k = 0; k < 6; ++k) ends.col(k) = body.BeamEndForces(b, Wrench::Unit(k));
    shear.push_back(ends.row(3) * tau);
    m.buckling.push_back({-ends.row(0), kPi * kPi * sc.e_pa * i_min / std::pow(0.5 * length, 2)});
    const double th = (g.first_beam_deg + 360.0 * b / g.beam_count) * kPi / 180.0;
    const Eigen::Vector3d dir(std::cos(th), std::sin(th), 0);
    SolidMember mb;
    mb.a_m = g.hub_radius_m * dir;
    mb.b_m = g.rim_radius_m * dir;
    mb.body_a = kPlatform;
    mb.body_b = kGround;
    mb.width_m = g.beam_width_m;
    mb.height_m = g.beam_height_m;
    mb.end_b_compliance = g.rim_compliance;
    m.members.push_back(mb);
    SketchSegment seg{g.hub_radius_m * dir, g.rim_radius_m * dir, {}};
    for (int i = 0; i <= 8; ++i) {
      std::array<Row6, 4> rows;
      const BeamFace faces[4] = {BeamFace::kTop, BeamFace::kBottom, BeamFace::kPlusY,
                                 BeamFace::kMinusY};
      for (int f = 0; f < 4; ++f) {
        rows[static_cast<std::size_t>(f)] =
            body.StrainMatrix(GaugeSite{b, length * i / 8.0, faces[f], 0, 0}).row(0);
      }
      seg.stations.push_back(rows);
    }
    m.sketch.push_back(seg);
  }
  m.stress_shear = Stack(shear);
  m.bridge_noise_mvv = bridge_noise_mvv;
  m.native_bandwidth_hz = 0.5 * rate_hz;
  return m;
}

DesignModel HubSpoke(const HubSpokeParams& p, const Readout& r) {
  FlexureSensorSpec spec;
  spec.name = "hub-spoke";
  spec.body.beam_count = p.beams;
  spec.body.hub_radius_m = p.hub_radius_m;
  spec.body.rim_radius_m = p.rim_radius_m;
  spec.body.beam_width_m = p.beam_width_m;
  spec.body.beam_height_m = p.beam_height_m;
  spec.body.first_beam_deg = 0;
  spec.body.e_pa = p.material.e_pa;
  spec.body.poisson = p.material.poisson;
  spec.body.shear_deformable = true;
  spec.body.elastic_roots = p.elastic_roots;
  spec.gauge.resistance_ohm = 350;
  spec.gauge.gauge_factor = r.gauge_factor;
  spec.rated = Wrench::Ones();
  spec.max_condition_number = 1e9;
  BridgeCircuit circuit;
  circuit.excitation_v = r.adc.excitation_v;
  AddBendingBridges(&spec, p.gauge_frac * (p.rim_radius_m - p.hub_radius_m), circuit);
  const PhysicalSensorModel model(spec);
  DesignModel m = FromPhysicalSensor(model, p.material, ReadoutNoiseMvv(r), r.adc.rate_hz);
  m.parameters["gauge_frac"] = p.gauge_frac;
  return m;
}

}  // namespace ftstack::sim::design
