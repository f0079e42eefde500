#include "sim/default_sensor.hpp"

#include "sim/sensor_description.hpp"

namespace ftstack::sim {

Wrench DefaultRated() {
  Wrench r;
  r << 200.0, 200.0, 400.0, 10.0, 10.0, 8.0;
  return r;
}

std::unique_ptr<SensorModel> MakeDefaultSensor() {
  return ParsePhysicalSensor(DefaultSensorJson(), "builtin:sim/sensors/default.json");
}

}  // namespace ftstack::sim
