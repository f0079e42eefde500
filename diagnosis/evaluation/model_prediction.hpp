// The diagnosis of a real recording against a sensor description's prediction (ftdiag --model).
#pragma once

#include <string>

#include "diagnosis/engine/data.hpp"

namespace ftstack::diag {

/// Reads REAL.csv and predicts its bridges with the model of the sensor description at
/// `sensor_path` ("builtin": the built-in sensor) from the real wrench and temp_C. Throws
/// DiagInputError naming the file at fault.
[[nodiscard]] DiagData LoadModelReal(const std::string& sensor_path, const std::string& real_path,
                                     ProgressFn progress = nullptr, void* user = nullptr);

}  // namespace ftstack::diag
