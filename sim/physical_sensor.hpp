// The physical sensor model: flexure body → gauge strains → exact Wheatstone bridges → mV/V.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "sim/flexure_body.hpp"
#include "sim/sensor_model.hpp"
#include "sim/strain_bridge.hpp"

namespace ftstack::sim {

/// One bridge: its circuit and which gauge sits in each arm (index into FlexureSensorSpec::gauges;
/// −1 for a completion resistor in the instrument). Active arms must hold gauges: R1 (quarter),
/// R1 and R2 (half), all four (full).
struct BridgeSpec {
  BridgeCircuit circuit;
  std::array<int, 4> arm_gauge{-1, -1, -1, -1};
};

/// Everything that defines a physical sensor.
struct FlexureSensorSpec {
  std::string name = "flexure";
  FlexureGeometry body;
  double modulus_tc_per_k = 0.0;  ///< relative change of E (and G) per K; strains scale by 1/(1+…)
  double allowable_strain = 0.0;       ///< material limit for warnings (0: no check)
  double max_condition_number = 10.0;  ///< warn above this (normalised sensitivity)
  GaugeType gauge;
  std::vector<GaugeSite> gauges;
  std::vector<BridgeSpec> bridges;  ///< 1 … 8 bridges, one ADC channel each
  Wrench rated = Wrench::Zero();    ///< rated range per axis, N and N·m, all > 0
};

/// Design figures of a sensor.
struct DesignReport {
  Eigen::Matrix<double, 6, 6> stiffness;  ///< hub stiffness, N/m, N·m/rad (mixed blocks)
  Eigen::MatrixXd sensitivity_mvv;        ///< N × 6, mV/V per N or N·m, small signal at 20 °C
  Eigen::MatrixXd rated_output_mvv;       ///< N × 6: sensitivity × rated range per axis
  double condition_number = 0;            ///< of rated_output_mvv (2-norm)
  /// Largest |grid strain| / |normal strain at a beam-end corner| at rated load, loads combined as
  /// commercial sensors rate them: the shares |Fz|/Fz_r + |Mxy|/Mxy_r ≤ 1 and |Fxy|/Fxy_r +
  /// |Mz|/Mz_r ≤ 1 both at their limit (Mxy, Fxy vector magnitudes).
  double max_gauge_strain = 0;
  double max_surface_strain = 0;
  double max_output_mvv = 0;          ///< largest |bridge output| under the same combined rule
  std::vector<std::string> warnings;  ///< allowable strain exceeded, bad conditioning, …
};

/// The physics model of a strain-gauge F/T sensor. Linear elastic body, exact bridge equation,
/// gauge thermal output and gauge-factor drift, modulus temperature coefficient, self-heating,
/// lead resistance. Construction throws std::invalid_argument on an inconsistent spec.
class PhysicalSensorModel final : public SensorModel {
 public:
  explicit PhysicalSensorModel(FlexureSensorSpec spec);

  [[nodiscard]] int channel_count() const override {
    return static_cast<int>(spec_.bridges.size());
  }
  [[nodiscard]] Eigen::VectorXd BridgeOutputs(const Wrench& w, double temperature_c) const override;
  [[nodiscard]] Wrench rated() const override { return spec_.rated; }
  [[nodiscard]] std::string name() const override { return spec_.name; }

  /// Writes the bridge outputs (mV/V) into out[0 … channel_count) without allocating.
  void BridgeOutputsInto(const Wrench& w, double temperature_c, double* out) const override;
  /// Grid (axial) strain of every gauge under w at 20 °C.
  [[nodiscard]] Eigen::VectorXd GaugeStrains(const Wrench& w) const;

  [[nodiscard]] const FlexureBody& body() const { return body_; }
  [[nodiscard]] const FlexureSensorSpec& spec() const { return spec_; }
  /// Stiffness, sensitivity, conditioning, rated strains and warnings.
  [[nodiscard]] DesignReport Report() const;

 private:
  FlexureSensorSpec spec_;
  FlexureBody body_;
  /// Rows 2g, 2g+1: axial and transverse strain of gauge g per unit wrench component.
  Eigen::MatrixXd strain_map_;
  std::vector<double> gauge_self_heating_k_;
};

/// Largest |c·w| over loads inside the combined rated envelope (see DesignReport).
[[nodiscard]] double CombinedRatedMax(const Eigen::Matrix<double, 1, 6>& c, const Wrench& rated);

/// Appends the classic layout to `spec`: per beam two full bending bridges of four axial gauges at
/// position_m from the hub end — first the out-of-plane bridge (R1, R3 on top, R2, R4 on the
/// bottom at ±width/4: senses Fz, Mx, My), then the in-plane bridge (R1, R3 on the +y side, R2, R4
/// on the −y side at ±height/4: senses Fx, Fy, Mz). Axial force and the other bending plane cancel.
void AddBendingBridges(FlexureSensorSpec* spec, double position_m, const BridgeCircuit& circuit);

}  // namespace ftstack::sim
