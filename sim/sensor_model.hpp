// Sensor models for simulation: wrench (N, N·m) and temperature → bridge outputs (mV/V).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>

#include "measurement/wrench.hpp"

namespace ftstack::sim {

/// A sensor as the simulator sees it: from load and temperature to bridge outputs.
class SensorModel {
 public:
  virtual ~SensorModel() = default;
  /// Number of bridges N (1 … 8).
  [[nodiscard]] virtual int channel_count() const = 0;
  /// Bridge outputs in mV/V for wrench `w` at body temperature `temperature_c` (°C).
  [[nodiscard]] virtual Eigen::VectorXd BridgeOutputs(const Wrench& w,
                                                      double temperature_c) const = 0;
  /// The same into out[0 … channel_count). Models on a sampling path (the simulated ADC's)
  /// override it without allocating; the default goes through BridgeOutputs.
  virtual void BridgeOutputsInto(const Wrench& w, double temperature_c, double* out) const;
  /// Rated range per axis (N, N·m), positive.
  [[nodiscard]] virtual Wrench rated() const = 0;
  /// Small-signal sensitivity d(mV/V)/d(wrench) at zero load and 20 °C (N × 6).
  [[nodiscard]] virtual Eigen::MatrixXd Sensitivity() const;
  [[nodiscard]] virtual std::string name() const = 0;
};

/// The linear model b = S·w + b0 (S in mV/V per N or N·m). The foundation's sensor model and a
/// reference for tests; the physics model (flexure body + gauges + bridges) replaces it.
class LinearSensorModel final : public SensorModel {
 public:
  LinearSensorModel(Eigen::MatrixXd sensitivity, Wrench rated, std::string name,
                    Eigen::VectorXd zero_mvv = Eigen::VectorXd());
  [[nodiscard]] int channel_count() const override { return static_cast<int>(s_.rows()); }
  [[nodiscard]] Eigen::VectorXd BridgeOutputs(const Wrench& w, double temperature_c) const override;
  void BridgeOutputsInto(const Wrench& w, double temperature_c, double* out) const override;
  [[nodiscard]] Wrench rated() const override { return rated_; }
  [[nodiscard]] Eigen::MatrixXd Sensitivity() const override { return s_; }
  [[nodiscard]] std::string name() const override { return name_; }

 private:
  Eigen::MatrixXd s_;
  Wrench rated_;
  std::string name_;
  Eigen::VectorXd zero_;
};

}  // namespace ftstack::sim
