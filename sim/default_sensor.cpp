#include "sim/default_sensor.hpp"

#include <cmath>
#include <numbers>

namespace ftstack::sim {

Wrench DefaultRated() {
  Wrench r;
  r << 200.0, 200.0, 400.0, 10.0, 10.0, 8.0;
  return r;
}

std::unique_ptr<SensorModel> MakeDefaultSensor() {
  const Wrench rated = DefaultRated();
  constexpr double kRatedMvv = 0.6;  // bridge output per term at rated load, mV/V
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < 6; ++i) {
    const double th = i * std::numbers::pi / 3.0;
    if (i % 2 == 0) {  // bending bridge: Fz and the moment about the tangent axis
      s(i, 2) = kRatedMvv / rated(2);
      s(i, 3) = kRatedMvv * std::sin(th) / rated(3);
      s(i, 4) = -kRatedMvv * std::cos(th) / rated(4);
    } else {  // shear bridge: tangential force and Mz
      s(i, 0) = -kRatedMvv * std::sin(th) / rated(0);
      s(i, 1) = kRatedMvv * std::cos(th) / rated(1);
      s(i, 5) = kRatedMvv / rated(5);
    }
  }
  // A few per cent of cross-talk, as machining and gauge placement leave it.
  const double xt[6][6] = {{0.02, -0.01, 0, 0.015, 0, -0.02},    {0, 0.01, -0.02, 0, 0.01, 0},
                           {-0.015, 0, 0.01, -0.01, 0.02, 0.01}, {0.01, 0.02, 0, 0, -0.015, 0},
                           {0, -0.02, 0.015, 0.01, 0, 0.02},     {0.02, 0, -0.01, 0.02, 0.01, 0}};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) s(i, j) += kRatedMvv * xt[i][j] / rated(j);
  }
  return std::make_unique<LinearSensorModel>(s, rated, "builtin-3beam-linear");
}

}  // namespace ftstack::sim
