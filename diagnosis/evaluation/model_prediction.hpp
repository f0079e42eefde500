// The diagnosis of a real recording against a sensor description's prediction (ftdiag --model).
#pragma once

#include <string>

#include "diagnosis/loader/data.hpp"
#include "measurement/units.hpp"

namespace ftstack::diag {

/// What decides the real recording's bridge unit: `cli` or the file's declaration; where neither
/// says and `cal_path` names the real sensor's calibration, the unit and converter it was fitted
/// from (the rule of `ftcal apply`: a conflicting declaration and values that cannot be that unit
/// are refused); else the format default (mV/V).
struct RealUnitSources {
  std::string cal_path;
  UnitOverrides cli;
};

/// The RealUnits of `sources` for a real recording (the calibration is read here; CalFileError).
/// The returned rule refers to `sources`, which must outlive it.
[[nodiscard]] RealUnits MakeRealUnits(const RealUnitSources& sources);

/// Reads REAL.csv and predicts its bridges with the model of the sensor description at
/// `sensor_path` ("builtin": the built-in sensor) from the real wrench and temp_C. Throws
/// DiagInputError naming the file at fault.
[[nodiscard]] DiagData LoadModelReal(const std::string& sensor_path, const std::string& real_path,
                                     ProgressFn progress = nullptr, void* user = nullptr,
                                     const RealUnitSources& units = {});

}  // namespace ftstack::diag
