#include "sim/sensor_model.hpp"

#include <stdexcept>

namespace ftstack::sim {

Eigen::MatrixXd SensorModel::Sensitivity() const {
  // Central differences at 1e-3 of rated load on each axis.
  const int n = channel_count();
  Eigen::MatrixXd s(n, 6);
  const Wrench r = rated();
  for (int j = 0; j < 6; ++j) {
    Wrench w = Wrench::Zero();
    const double h = 1e-3 * r(j);
    w(j) = h;
    const Eigen::VectorXd plus = BridgeOutputs(w, 20.0);
    w(j) = -h;
    const Eigen::VectorXd minus = BridgeOutputs(w, 20.0);
    s.col(j) = (plus - minus) / (2 * h);
  }
  return s;
}

LinearSensorModel::LinearSensorModel(Eigen::MatrixXd sensitivity, Wrench rated, std::string name,
                                     Eigen::VectorXd zero_mvv)
    : s_(std::move(sensitivity)),
      rated_(rated),
      name_(std::move(name)),
      zero_(std::move(zero_mvv)) {
  if (s_.cols() != 6 || s_.rows() < 1 || s_.rows() > 8) {
    throw std::invalid_argument("sensitivity matrix must be N x 6 with 1 <= N <= 8");
  }
  if (zero_.size() == 0) zero_ = Eigen::VectorXd::Zero(s_.rows());
  if (zero_.size() != s_.rows()) throw std::invalid_argument("zero offset needs N entries");
}

Eigen::VectorXd LinearSensorModel::BridgeOutputs(const Wrench& w, double /*temperature_c*/) const {
  return s_ * w + zero_;
}

void LinearSensorModel::BridgeOutputsInto(const Wrench& w, double /*temperature_c*/,
                                          double* out) const {
  Eigen::Map<Eigen::VectorXd> dst(out, s_.rows());
  dst.noalias() = s_ * w;
  dst += zero_;
}

void SensorModel::BridgeOutputsInto(const Wrench& w, double temperature_c, double* out) const {
  const Eigen::VectorXd b = BridgeOutputs(w, temperature_c);
  for (Eigen::Index i = 0; i < b.size(); ++i) out[i] = b(i);
}

}  // namespace ftstack::sim
