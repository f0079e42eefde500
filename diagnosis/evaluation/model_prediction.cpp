#include "diagnosis/evaluation/model_prediction.hpp"

#include <memory>

#include "calibration/file/recorded_unit.hpp"
#include "sim/sensor_description.hpp"

namespace ftstack::diag {

RealUnits MakeRealUnits(const RealUnitSources& sources) {
  RealUnits units;
  units.cli = sources.cli;
  if (sources.cal_path.empty()) return units;
  auto cal = std::make_shared<const cal::CalFile>(cal::LoadCalFile(sources.cal_path));
  if (cal->input_unit != "mV/V") {
    throw DiagInputError(sources.cal_path + ": input unit " + cal->input_unit +
                         ": the diagnosis works in mV/V and this calibration's unit has no "
                         "known mV/V scale");
  }
  units.rule = [cal, &sources](Recording* real) {
    const InputUnit u = cal::UnitForCalibration(*real, sources.cli, *cal, sources.cal_path);
    (void)cal::PrepareApplyInput(real, sources.cli, *cal, sources.cal_path);
    return u;
  };
  return units;
}

DiagData LoadModelReal(const std::string& sensor_path, const std::string& real_path,
                       ProgressFn progress, void* user, const RealUnitSources& units) {
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
      progress, user, MakeRealUnits(units));
}

}  // namespace ftstack::diag
