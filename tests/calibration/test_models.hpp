// Test-only sensor models with known non-idealities (quadratic response, temperature drift).
#pragma once

#include <Eigen/Dense>
#include <memory>

#include "sim/default_sensor.hpp"
#include "sim/sensor_description.hpp"
#include "sim/sensor_model.hpp"

namespace ftstack::testing {

/// Wraps a linear model: every bridge output u = S·w + z becomes u + k_c·(S·w)_c² (a bridge
/// nonlinearity of k_c per mV/V) + zero drift d_c·ΔT, gain drift (1 + g_c·ΔT) on the load part.
class DistortedSensor final : public sim::SensorModel {
 public:
  DistortedSensor(const sim::SensorModel& base, Eigen::VectorXd quad_per_mvv,
                  Eigen::VectorXd zero_drift_mvv_per_c, Eigen::VectorXd gain_drift_per_c)
      : base_(base),
        s_(base.Sensitivity()),
        z_(base.BridgeOutputs(Wrench::Zero(), 20.0)),
        k_(std::move(quad_per_mvv)),
        d_(std::move(zero_drift_mvv_per_c)),
        g_(std::move(gain_drift_per_c)) {}
  [[nodiscard]] int channel_count() const override { return base_.channel_count(); }
  [[nodiscard]] Eigen::VectorXd BridgeOutputs(const Wrench& w, double t_c) const override {
    const Eigen::VectorXd u = s_ * w;
    const double dt = t_c - 20.0;
    Eigen::VectorXd out(u.size());
    for (Eigen::Index c = 0; c < u.size(); ++c) {
      out(c) = z_(c) + (u(c) + k_(c) * u(c) * u(c)) * (1.0 + g_(c) * dt) + d_(c) * dt;
    }
    return out;
  }
  [[nodiscard]] Wrench rated() const override { return base_.rated(); }
  [[nodiscard]] std::string name() const override { return "distorted-" + base_.name(); }

 private:
  const sim::SensorModel& base_;
  Eigen::MatrixXd s_;
  Eigen::VectorXd z_;
  Eigen::VectorXd k_;
  Eigen::VectorXd d_;
  Eigen::VectorXd g_;
};

/// Noise floor per axis (N, N·m): channel noise (white + ADC rounding) carried through the true
/// inverse sensitivity pinv(S) — the error a perfect calibration still has.
inline Eigen::Matrix<double, 6, 1> NoiseFloor(const sim::SensorDescription& d) {
  const Eigen::MatrixXd m =
      d.model->Sensitivity().completeOrthogonalDecomposition().pseudoInverse();
  const double full_scale_mvv = 1000.0 * d.adc.reference_ratio / d.adc_gain;
  const double counts_per_mvv =
      static_cast<double>((std::int64_t{1} << (d.adc.resolution_bits - 1)) - 1) / full_scale_mvv;
  const double var =
      d.adc.noise_rms_mvv * d.adc.noise_rms_mvv + 1.0 / (12.0 * counts_per_mvv * counts_per_mvv);
  Eigen::Matrix<double, 6, 1> f;
  for (int a = 0; a < 6; ++a) f(a) = std::sqrt(m.row(a).squaredNorm() * var);
  return f;
}

}  // namespace ftstack::testing
