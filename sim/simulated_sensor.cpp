#include "sim/simulated_sensor.hpp"

namespace ftstack::sim {

bool SimulatedSensor::Sample(double t_s, double* bridge_mvv, double* temperature_c) {
  Wrench w;
  double temp = 20.0;
  if (!source_.At(t_s, &w, &temp)) return false;
  last_wrench_ = w;
  model_.BridgeOutputsInto(w, temp, bridge_mvv);  // no allocation: runs in the sampling thread
  *temperature_c = temp;
  return true;
}

}  // namespace ftstack::sim
