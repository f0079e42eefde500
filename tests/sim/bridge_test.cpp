// Gauges and Wheatstone bridges against closed forms: exact equation, linearisation, lead wires.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/strain_bridge.hpp"

namespace ftstack::sim {
namespace {

constexpr double kR = 350.0;

BridgeCircuit Circuit(BridgeKind k, BridgeWiring w, double lead = 0.0, double completion = kR) {
  BridgeCircuit c;
  c.kind = k;
  c.wiring = w;
  c.lead_ohm = lead;
  c.completion_ohm = completion;
  c.excitation_v = 5.0;
  return c;
}

TEST(Bridge, QuarterBridgeIsTheExactDividerAndItsNonlinearityIsXOver2PlusX) {
  const BridgeCircuit c = Circuit(BridgeKind::kQuarter, BridgeWiring::kThreeWire);
  for (double x : {-0.004, -0.002, 0.0005, 0.002, 0.004}) {
    const double exact = BridgeOutputMvv(c, {kR * (1 + x), 0, 0, 0});
    // V/V = (1+x)/(2+x) − 1/2 = x/(4 + 2x) (Hoffmann, "An Introduction to Stress Analysis and
    // Transducer Design using Strain Gauges", quarter-bridge equation).
    EXPECT_NEAR(exact, 1000 * x / (4 + 2 * x), 1e-12);
    const double linear = 1000 * x / 4;
    EXPECT_NEAR((linear - exact) / linear, x / (2 + x), 1e-9);
  }
  // GF 2 at 1000 µε: x = 0.002, the familiar ≈ 0.1 % quarter-bridge nonlinearity.
  const double x = 2.0 * 1000e-6;
  const double exact = BridgeOutputMvv(c, {kR * (1 + x), 0, 0, 0});
  EXPECT_NEAR(1 - exact / (1000 * x / 4), 0.001, 0.000001);
}

TEST(Bridge, HalfAndFullBendingBridgesAreExactlyLinear) {
  const BridgeCircuit half = Circuit(BridgeKind::kHalf, BridgeWiring::kThreeWire);
  const BridgeCircuit full = Circuit(BridgeKind::kFull, BridgeWiring::kSixWire);
  for (double x : {-0.01, -0.002, 0.001, 0.003, 0.01}) {
    EXPECT_NEAR(BridgeOutputMvv(half, {kR * (1 + x), kR * (1 - x), 0, 0}), 1000 * x / 2, 1e-12);
    EXPECT_NEAR(BridgeOutputMvv(full, {kR * (1 + x), kR * (1 - x), kR * (1 + x), kR * (1 - x)}),
                1000 * x, 1e-12);
  }
}

TEST(Bridge, SmallStrainLinearisationHoldsToSecondOrder) {
  const BridgeCircuit full = Circuit(BridgeKind::kFull, BridgeWiring::kSixWire);
  // Unequal arm changes: the exact output differs from (Δ1 − Δ2 + Δ3 − Δ4)/4 by O(Δ²).
  const double d[4] = {0.0021, -0.0007, 0.0013, 0.0004};
  const double exact =
      BridgeOutputMvv(full, {kR * (1 + d[0]), kR * (1 + d[1]), kR * (1 + d[2]), kR * (1 + d[3])});
  const double linear = 1000 * (d[0] - d[1] + d[2] - d[3]) / 4;
  const double second_order = 1000 * 0.25 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
  EXPECT_LT(std::abs(exact - linear), second_order);
  EXPECT_GT(std::abs(exact - linear), 1e-3 * second_order);  // and it is really nonlinear
}

// Sensitivity of the output to a small change of R1, relative to the lead-free bridge.
double Desensitisation(const BridgeCircuit& c, BridgeKind k) {
  const double h = 1e-7;
  auto arms = [&](double x) -> std::array<double, 4> {
    if (k == BridgeKind::kHalf) return {kR * (1 + x), kR * (1 - x), 0, 0};
    if (k == BridgeKind::kFull) return {kR * (1 + x), kR * (1 - x), kR * (1 + x), kR * (1 - x)};
    return {kR * (1 + x), 0, 0, 0};
  };
  BridgeCircuit ideal = c;
  ideal.lead_ohm = 0;
  ideal.completion_ohm = kR;
  const double s = BridgeOutputMvv(c, arms(h)) - BridgeOutputMvv(c, arms(-h));
  const double s0 = BridgeOutputMvv(ideal, arms(h)) - BridgeOutputMvv(ideal, arms(-h));
  return s / s0;
}

TEST(Bridge, LeadWireDesensitisationMatchesTheClosedForms) {
  const double rl = 2.5;
  // Full bridge, 4 wires: the excitation leads divide the supply: R/(R + 2·RL).
  EXPECT_NEAR(
      Desensitisation(Circuit(BridgeKind::kFull, BridgeWiring::kFourWire, rl), BridgeKind::kFull),
      kR / (kR + 2 * rl), 1e-7);
  // Full bridge, 6 wires: the sense lines remove the loss.
  EXPECT_NEAR(
      Desensitisation(Circuit(BridgeKind::kFull, BridgeWiring::kSixWire, rl), BridgeKind::kFull),
      1.0, 1e-9);
  // Quarter bridge, 3 wires: R/(R + RL) (Vishay TN-514).
  EXPECT_NEAR(Desensitisation(Circuit(BridgeKind::kQuarter, BridgeWiring::kThreeWire, rl),
                              BridgeKind::kQuarter),
              kR / (kR + rl), 1e-6);
  // Quarter bridge, 2 wires, completion balanced to R + 2RL: R/(R + 2RL) (TN-514).
  EXPECT_NEAR(
      Desensitisation(Circuit(BridgeKind::kQuarter, BridgeWiring::kTwoWire, rl, kR + 2 * rl),
                      BridgeKind::kQuarter),
      kR / (kR + 2 * rl), 1e-6);
  // Half bridge, 3 wires: one lead in each active arm: R/(R + RL).
  EXPECT_NEAR(
      Desensitisation(Circuit(BridgeKind::kHalf, BridgeWiring::kThreeWire, rl), BridgeKind::kHalf),
      kR / (kR + rl), 1e-6);
  // A 2-wire quarter bridge also reads an offset: 2RL in the gauge arm, (R+2RL)/(2R+2RL) − 1/2.
  EXPECT_NEAR(
      BridgeOutputMvv(Circuit(BridgeKind::kQuarter, BridgeWiring::kTwoWire, rl), {kR, 0, 0, 0}),
      1000 * ((kR + 2 * rl) / (2 * kR + 2 * rl) - 0.5), 1e-12);
}

TEST(Bridge, RejectsWiringThatDoesNotExist) {
  EXPECT_THROW(ValidateBridge(Circuit(BridgeKind::kFull, BridgeWiring::kTwoWire)),
               std::invalid_argument);
  EXPECT_THROW(ValidateBridge(Circuit(BridgeKind::kQuarter, BridgeWiring::kSixWire)),
               std::invalid_argument);
  EXPECT_THROW(ValidateBridge(Circuit(BridgeKind::kHalf, BridgeWiring::kFourWire)),
               std::invalid_argument);
  BridgeCircuit c = Circuit(BridgeKind::kFull, BridgeWiring::kSixWire, std::nan(""));
  EXPECT_THROW(ValidateBridge(c), std::invalid_argument);
  EXPECT_NO_THROW(ValidateBridge(Circuit(BridgeKind::kQuarter, BridgeWiring::kTwoWire)));
}

TEST(Gauge, TransverseSensitivityCancelsInTheCalibrationField) {
  GaugeType g;
  g.gauge_factor = 2.1;
  g.transverse_sensitivity = 0.02;
  g.calibration_poisson = 0.285;
  // In the manufacturer's uniaxial-stress field (ε_t = −ν₀·ε_a) the gauge reads GF·ε_a exactly.
  EXPECT_NEAR(GaugeRelativeChange(g, 1e-3, -0.285e-3, kGaugeReferenceC), 2.1e-3, 1e-15);
  // In a pure transverse strain it reads GF·Kt·ε_t/(1 − ν₀·Kt) (Vishay TN-509).
  EXPECT_NEAR(GaugeRelativeChange(g, 0, 1e-3, kGaugeReferenceC), 2.1 * 0.02e-3 / (1 - 0.285 * 0.02),
              1e-15);
}

TEST(Gauge, ThermalOutputAndGaugeFactorDrift) {
  GaugeType g;
  g.gauge_factor = 2.0;
  g.thermal_output_per_k = 1.5e-6;
  g.gauge_factor_tc_per_k = 1e-4;
  const double dt = 30.0;
  EXPECT_NEAR(GaugeRelativeChange(g, 0, 0, kGaugeReferenceC + dt),
              2.0 * (1 + 1e-4 * dt) * 1.5e-6 * dt, 1e-15);
  EXPECT_NEAR(GaugeRelativeChange(g, 500e-6, 0, kGaugeReferenceC + dt) -
                  GaugeRelativeChange(g, 0, 0, kGaugeReferenceC + dt),
              2.0 * (1 + 1e-4 * dt) * 500e-6, 1e-15);
}

TEST(Gauge, SelfHeatingIsPowerTimesThermalResistance) {
  GaugeType g;
  g.resistance_ohm = 120;
  g.self_heating_k_per_w = 40;
  BridgeCircuit c = Circuit(BridgeKind::kFull, BridgeWiring::kSixWire);
  c.excitation_v = 10;
  EXPECT_NEAR(SelfHeatingK(c, g), 5.0 * 5.0 / 120 * 40, 1e-12);
}

}  // namespace
}  // namespace ftstack::sim
