// The bridge-unit options every tool reading bridge columns shares (recording-format.md,
// "Declared bridge units"): --bridge-unit, --converter, --excitation-v.
#pragma once

#include <CLI/CLI.hpp>

#include "measurement/units.hpp"

namespace ftstack::tools {

/// Adds the unit options to `sub`; they override the recording's metadata.
inline void AddUnitOptions(CLI::App* sub, UnitOverrides* units) {
  sub->add_option("--bridge-unit", units->unit,
                  "unit of the b* columns: mV/V, V or counts (overrides # bridge_unit)");
  sub->add_option("--converter", units->converter,
                  "converter of counts: \"bits=10,coding=unsigned|signed|offset-binary,gain=1,"
                  "ratiometric=yes,reference_ratio=1,reference_v=…,full_scale_mvv=…\"");
  sub->add_option("--excitation-v", units->excitation_v, "bridge excitation, V")
      ->check(CLI::PositiveNumber);
}

}  // namespace ftstack::tools
