// The JSON report of a diagnosis, schema "ftdiag-report/1" (docs/spec/diagnosis.md).
#pragma once

#include <nlohmann/json.hpp>

#include "diagnosis/engine/diagnose.hpp"

namespace ftstack::diag {

/// The JSON report, schema "ftdiag-report/1" (docs/spec/diagnosis.md), plus documented extra keys.
[[nodiscard]] nlohmann::json ToJson(const Report& report);

}  // namespace ftstack::diag
