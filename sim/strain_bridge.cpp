#include "sim/strain_bridge.hpp"

#include <cmath>
#include <stdexcept>

namespace ftstack::sim {

double GaugeRelativeChange(const GaugeType& g, double axial_strain, double transverse_strain,
                           double temperature_c) {
  const double dt = temperature_c - kGaugeReferenceC;
  const double gf = g.gauge_factor * (1.0 + g.gauge_factor_tc_per_k * dt);
  const double kt = g.transverse_sensitivity;
  const double mech = (axial_strain + kt * transverse_strain) / (1.0 - g.calibration_poisson * kt);
  return gf * (mech + g.thermal_output_per_k * dt);
}

void ValidateBridge(const BridgeCircuit& c) {
  const bool ok_wiring =
      (c.kind == BridgeKind::kQuarter &&
       (c.wiring == BridgeWiring::kTwoWire || c.wiring == BridgeWiring::kThreeWire)) ||
      (c.kind == BridgeKind::kHalf && c.wiring == BridgeWiring::kThreeWire) ||
      (c.kind == BridgeKind::kFull &&
       (c.wiring == BridgeWiring::kFourWire || c.wiring == BridgeWiring::kSixWire));
  if (!ok_wiring) {
    throw std::invalid_argument(
        "bridge wiring: quarter bridges use 2 or 3 wires, half bridges 3, full bridges 4 or 6");
  }
  if (!std::isfinite(c.lead_ohm) || c.lead_ohm < 0) {
    throw std::invalid_argument("bridge: lead_ohm must be finite and >= 0");
  }
  if (!std::isfinite(c.completion_ohm) || c.completion_ohm < 0) {
    throw std::invalid_argument("bridge: completion_ohm must be finite and >= 0");
  }
  if (!std::isfinite(c.excitation_v) || c.excitation_v <= 0) {
    throw std::invalid_argument("bridge: excitation_v must be finite and > 0");
  }
}

double BridgeOutputMvv(const BridgeCircuit& c, const std::array<double, 4>& arm) {
  const double rl = c.lead_ohm;
  double r1 = arm[0];
  double r2 = arm[1];
  double r3 = arm[2];
  double r4 = arm[3];
  double v_bridge = 1.0;  // bridge-top voltage over the excitation (or over the sensed voltage)
  switch (c.kind) {
    case BridgeKind::kQuarter:
      r2 = r3 = r4 = c.completion_ohm;
      if (c.wiring == BridgeWiring::kTwoWire) {
        r1 += 2 * rl;  // both leads in the gauge arm
      } else {
        r1 += rl;  // one lead in the gauge arm, one in the adjacent arm, the sense lead idle
        r2 += rl;
      }
      break;
    case BridgeKind::kHalf:
      r3 = r4 = c.completion_ohm;
      r1 += rl;  // the excitation leads, one in each active arm; the mid-point lead is idle
      r2 += rl;
      break;
    case BridgeKind::kFull:
      if (c.wiring == BridgeWiring::kFourWire) {
        const double r_in = (r1 + r2) * (r3 + r4) / (r1 + r2 + r3 + r4);
        v_bridge = r_in / (r_in + 2 * rl);  // the excitation leads drop part of the supply
      }
      break;
  }
  return 1000.0 * v_bridge * (r1 / (r1 + r2) - r4 / (r3 + r4));
}

double SelfHeatingK(const BridgeCircuit& c, const GaugeType& g) {
  const double v = 0.5 * c.excitation_v;
  return v * v / g.resistance_ohm * g.self_heating_k_per_w;
}

}  // namespace ftstack::sim
