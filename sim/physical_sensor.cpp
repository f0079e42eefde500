#include "sim/physical_sensor.hpp"

#include <cmath>
#include <stdexcept>

namespace ftstack::sim {
namespace {

int ActiveArms(BridgeKind k) {
  switch (k) {
    case BridgeKind::kQuarter:
      return 1;
    case BridgeKind::kHalf:
      return 2;
    case BridgeKind::kFull:
      return 4;
  }
  return 4;
}

void ValidateGauge(const GaugeType& g) {
  const bool ok =
      std::isfinite(g.resistance_ohm) && g.resistance_ohm > 0 && std::isfinite(g.gauge_factor) &&
      g.gauge_factor > 0 && std::isfinite(g.transverse_sensitivity) &&
      std::abs(g.transverse_sensitivity) < 0.5 && std::isfinite(g.calibration_poisson) &&
      std::isfinite(g.thermal_output_per_k) && std::isfinite(g.gauge_factor_tc_per_k) &&
      std::isfinite(g.self_heating_k_per_w) && g.self_heating_k_per_w >= 0;
  if (!ok) throw std::invalid_argument("gauge: values must be finite, R and GF > 0, |Kt| < 0.5");
}

}  // namespace

PhysicalSensorModel::PhysicalSensorModel(FlexureSensorSpec spec)
    : spec_(std::move(spec)), body_(spec_.body) {
  ValidateGauge(spec_.gauge);
  if (spec_.bridges.empty() || spec_.bridges.size() > 8) {
    throw std::invalid_argument("sensor needs 1 … 8 bridges");
  }
  for (int k = 0; k < 6; ++k) {
    if (!std::isfinite(spec_.rated(k)) || spec_.rated(k) <= 0) {
      throw std::invalid_argument("rated ranges must be finite and > 0");
    }
  }
  if (!std::isfinite(spec_.modulus_tc_per_k) || !std::isfinite(spec_.allowable_strain) ||
      spec_.allowable_strain < 0 || !std::isfinite(spec_.max_condition_number)) {
    throw std::invalid_argument("material temperature coefficient / allowable strain not valid");
  }
  const int ng = static_cast<int>(spec_.gauges.size());
  strain_map_.resize(2 * ng, 6);
  for (int g = 0; g < ng; ++g) {
    strain_map_.middleRows(2 * g, 2) =
        body_.StrainMatrix(spec_.gauges[static_cast<std::size_t>(g)]);
  }
  gauge_self_heating_k_.assign(static_cast<std::size_t>(ng), 0.0);
  std::vector<int> used(static_cast<std::size_t>(ng), 0);
  for (std::size_t b = 0; b < spec_.bridges.size(); ++b) {
    BridgeSpec& br = spec_.bridges[b];
    if (br.circuit.completion_ohm == 0) br.circuit.completion_ohm = spec_.gauge.resistance_ohm;
    ValidateBridge(br.circuit);
    const int active = ActiveArms(br.circuit.kind);
    for (int a = 0; a < 4; ++a) {
      const int gi = br.arm_gauge[static_cast<std::size_t>(a)];
      if (a < active) {
        if (gi < 0 || gi >= ng) {
          throw std::invalid_argument("bridge " + std::to_string(b) + " arm R" +
                                      std::to_string(a + 1) + " needs a gauge index 0 … " +
                                      std::to_string(ng - 1));
        }
        if (used[static_cast<std::size_t>(gi)]++ != 0) {
          throw std::invalid_argument("gauge " + std::to_string(gi) + " is wired into two arms");
        }
        gauge_self_heating_k_[static_cast<std::size_t>(gi)] = SelfHeatingK(br.circuit, spec_.gauge);
      } else if (gi != -1) {
        throw std::invalid_argument("bridge " + std::to_string(b) + " arm R" +
                                    std::to_string(a + 1) +
                                    " is a completion resistor for this bridge kind");
      }
    }
  }
}

void PhysicalSensorModel::BridgeOutputsInto(const Wrench& w, double temperature_c,
                                            double* out) const {
  // Uniform temperature: E(T) = E·(1 + κ·ΔT) leaves stresses unchanged and scales strains.
  const double strain_scale =
      1.0 / (1.0 + spec_.modulus_tc_per_k * (temperature_c - kGaugeReferenceC));
  const double r0 = spec_.gauge.resistance_ohm;
  for (std::size_t b = 0; b < spec_.bridges.size(); ++b) {
    const BridgeSpec& br = spec_.bridges[b];
    std::array<double, 4> arm{r0, r0, r0, r0};
    for (std::size_t a = 0; a < 4; ++a) {
      const int gi = br.arm_gauge[a];
      if (gi < 0) continue;
      const auto row = static_cast<Eigen::Index>(2 * gi);
      const double ea = strain_scale * strain_map_.row(row).dot(w);
      const double et = strain_scale * strain_map_.row(row + 1).dot(w);
      const double tg = temperature_c + gauge_self_heating_k_[static_cast<std::size_t>(gi)];
      arm[a] = r0 * (1.0 + GaugeRelativeChange(spec_.gauge, ea, et, tg));
    }
    out[b] = BridgeOutputMvv(br.circuit, arm);
  }
}

Eigen::VectorXd PhysicalSensorModel::BridgeOutputs(const Wrench& w, double temperature_c) const {
  Eigen::VectorXd out(channel_count());
  BridgeOutputsInto(w, temperature_c, out.data());
  return out;
}

Eigen::VectorXd PhysicalSensorModel::GaugeStrains(const Wrench& w) const {
  Eigen::VectorXd e(static_cast<Eigen::Index>(spec_.gauges.size()));
  for (Eigen::Index g = 0; g < e.size(); ++g) e(g) = strain_map_.row(2 * g).dot(w);
  return e;
}

DesignReport PhysicalSensorModel::Report() const {
  DesignReport r;
  r.stiffness = body_.Stiffness();
  r.sensitivity_mvv = Sensitivity();
  r.rated_output_mvv = r.sensitivity_mvv * spec_.rated.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(r.rated_output_mvv);
  const auto& sv = svd.singularValues();
  r.condition_number = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  for (Eigen::Index g = 0; g < static_cast<Eigen::Index>(spec_.gauges.size()); ++g) {
    r.max_gauge_strain =
        std::max(r.max_gauge_strain, CombinedRatedMax(strain_map_.row(2 * g), spec_.rated));
  }
  for (Eigen::Index b = 0; b < r.sensitivity_mvv.rows(); ++b) {
    r.max_output_mvv =
        std::max(r.max_output_mvv, CombinedRatedMax(r.sensitivity_mvv.row(b), spec_.rated));
  }
  r.max_surface_strain = body_.MaxSurfaceStrain(
      [this](const Eigen::Matrix<double, 1, 6>& c) { return CombinedRatedMax(c, spec_.rated); });
  if (spec_.allowable_strain > 0 && r.max_surface_strain > spec_.allowable_strain) {
    r.warnings.push_back("strain at rated load " + std::to_string(r.max_surface_strain * 1e6) +
                         " µε exceeds the allowable " +
                         std::to_string(spec_.allowable_strain * 1e6) + " µε");
  }
  if (channel_count() < 6) {
    r.warnings.push_back("fewer than 6 bridges: the six wrench components cannot all be sensed");
  } else if (!(r.condition_number <= spec_.max_condition_number)) {
    r.warnings.push_back("badly conditioned for 6-axis sensing: condition number " +
                         std::to_string(r.condition_number) + " > " +
                         std::to_string(spec_.max_condition_number));
  }
  return r;
}

double CombinedRatedMax(const Eigen::Matrix<double, 1, 6>& c, const Wrench& rated) {
  const double fz = std::abs(c(2)) * rated(2);
  const double mxy = std::hypot(c(3) * rated(3), c(4) * rated(4));
  const double fxy = std::hypot(c(0) * rated(0), c(1) * rated(1));
  const double mz = std::abs(c(5)) * rated(5);
  return std::max(fz, mxy) + std::max(fxy, mz);
}

void AddBendingBridges(FlexureSensorSpec* spec, double position_m, const BridgeCircuit& circuit) {
  const double qb = 0.25 * spec->body.beam_width_m;
  const double qh = 0.25 * spec->body.beam_height_m;
  for (int i = 0; i < spec->body.beam_count; ++i) {
    for (int plane = 0; plane < 2; ++plane) {
      const BeamFace tension = plane == 0 ? BeamFace::kTop : BeamFace::kPlusY;
      const BeamFace compression = plane == 0 ? BeamFace::kBottom : BeamFace::kMinusY;
      const double q = plane == 0 ? qb : qh;
      const int first = static_cast<int>(spec->gauges.size());
      spec->gauges.push_back({i, position_m, tension, -q, 0.0});      // R1
      spec->gauges.push_back({i, position_m, compression, -q, 0.0});  // R2
      spec->gauges.push_back({i, position_m, tension, q, 0.0});       // R3
      spec->gauges.push_back({i, position_m, compression, q, 0.0});   // R4
      spec->bridges.push_back({circuit, {first, first + 1, first + 2, first + 3}});
    }
  }
}

}  // namespace ftstack::sim
