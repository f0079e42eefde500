#include "diagnosis/evaluation/model_prediction.hpp"

#include "sim/sensor_description.hpp"

namespace ftstack::diag {

DiagData LoadModelReal(const std::string& sensor_path, const std::string& real_path,
                       ProgressFn progress, void* user) {
  sim::SensorDescription desc;
  try {
    desc = sim::LoadSensorDescription(sensor_path);
  } catch (const std::exception& e) {
    throw DiagInputError(e.what());
  }
  const sim::SensorModel& model = *desc.model;
  return LoadPredictedReal(
      real_path, sensor_path.empty() ? "builtin" : sensor_path, model.channel_count(),
      [&model](const Wrench& w, double temperature_c, double* out) {
        model.BridgeOutputsInto(w, temperature_c, out);
      },
      progress, user);
}

}  // namespace ftstack::diag
