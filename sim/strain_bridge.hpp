// Foil strain gauges and Wheatstone bridges: exact bridge equation, lead wires, self-heating, mV/V.
#pragma once

#include <array>
#include <cstdint>

namespace ftstack::sim {

/// Reference temperature of gauge data (gauge factor, thermal output), °C.
inline constexpr double kGaugeReferenceC = 20.0;

/// A foil strain gauge type. ΔR/R = GF(T)·[(ε_a + K_t·ε_t)/(1 − ν₀·K_t) + α_app·(T − 20 °C)]
/// with GF(T) = GF·(1 + gauge_factor_tc_per_k·(T − 20 °C)) (Vishay Tech Notes TN-509, TN-504:
/// transverse sensitivity referred to the manufacturer's calibration beam of Poisson ratio ν₀).
struct GaugeType {
  double resistance_ohm = 120.0;        ///< unstrained resistance at 20 °C
  double gauge_factor = 2.0;            ///< as calibrated on a beam with ν₀
  double transverse_sensitivity = 0.0;  ///< K_t (e.g. 0.005 for 0.5 %)
  double calibration_poisson = 0.285;   ///< ν₀ of the gauge-factor calibration beam
  double thermal_output_per_k = 0.0;    ///< apparent strain per K on the body material, 1/K
  double gauge_factor_tc_per_k = 0.0;   ///< relative change of GF per K
  double self_heating_k_per_w = 0.0;    ///< gauge temperature rise per W dissipated in it, K/W
};

/// ΔR/R of a gauge with grid strain ε_a, transverse strain ε_t, at grid temperature temperature_c.
[[nodiscard]] double GaugeRelativeChange(const GaugeType& g, double axial_strain,
                                         double transverse_strain, double temperature_c);

enum class BridgeKind : std::uint8_t { kQuarter, kHalf, kFull };
/// Lead wiring between sensor and instrument. Quarter: 2- or 3-wire; half: 3-wire; full: 4-wire
/// (excitation pair, signal pair) or 6-wire (adds a sense pair: the reference follows the
/// excitation at the bridge).
enum class BridgeWiring : std::uint8_t { kTwoWire, kThreeWire, kFourWire, kSixWire };

/// The circuit of one bridge. Arms R1 … R4 in the convention where, for small changes,
/// V_out/V_exc ≈ (ΔR1/R1 − ΔR2/R2 + ΔR3/R3 − ΔR4/R4)/4: V_out = V_exc_bridge·(R1/(R1+R2) −
/// R4/(R3+R4)), R1 and R4 on the low side. Active arms sit on the sensor: R1 (quarter), R1 and
/// R2 (half), all four (full); the others are completion resistors in the instrument.
struct BridgeCircuit {
  BridgeKind kind = BridgeKind::kFull;
  BridgeWiring wiring = BridgeWiring::kSixWire;
  double lead_ohm = 0.0;        ///< resistance of one lead wire, Ω
  double completion_ohm = 0.0;  ///< completion resistors (0: equal to the gauge resistance)
  double excitation_v = 5.0;    ///< excitation at the instrument, V
};

/// Throws std::invalid_argument when the wiring does not exist for the kind or values are bad.
void ValidateBridge(const BridgeCircuit& c);

/// Exact bridge output in mV/V of the instrument's excitation (of the sensed bridge voltage for
/// 6-wire), from the resistances of the four arms as they sit in the circuit (the completion arms
/// are taken from `c`, the values passed for them are ignored).
[[nodiscard]] double BridgeOutputMvv(const BridgeCircuit& c, const std::array<double, 4>& arm_ohm);

/// Steady temperature rise of each active gauge from its own dissipation, K: P = (V_exc/2)²/R
/// per gauge (balanced bridge, leads neglected) times the gauge's K/W.
[[nodiscard]] double SelfHeatingK(const BridgeCircuit& c, const GaugeType& g);

}  // namespace ftstack::sim
