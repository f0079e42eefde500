#include "calibration/fit/apply.hpp"

#include <algorithm>
#include <cmath>

#include "calibration/file/recorded_unit.hpp"
#include "firmware/core.hpp"

namespace ftstack::cal {

Recording ApplyCalibration(const CalFile& cal, const Recording& in) {
  const std::size_t n = cal.cal.channel_count;
  if (in.BridgeCount() < n) {
    throw CalFileError(in.path + ": has " + std::to_string(in.BridgeCount()) +
                       " bridge columns, the calibration needs " + std::to_string(n));
  }
  fw::WrenchCore core;
  core.SetLimits(fw::CoreLimits{0, 0});  // a recording may legitimately repeat values
  core.SetCalibration(ToFixed(cal, cal.adc));
  const double counts_per_input = fw::CountsPerMvv(cal.adc);
  std::vector<const std::vector<double>*> b;
  for (std::size_t c = 0; c < n; ++c) b.push_back(&in.Column("b" + std::to_string(c)));
  const std::size_t rows = in.rows();
  std::vector<std::vector<double>> out(7, std::vector<double>(rows));
  std::vector<double> status(rows);
  const bool has_t = in.Has("t");
  const std::vector<double>* temp = in.Has("temp_C") ? &in.Column("temp_C") : nullptr;
  hal::AdcSample sample{};
  sample.channel_count = static_cast<std::uint8_t>(n);
  hal::AdcInfo rails = cal.adc;
  fw::CoreOutput o{};
  for (std::size_t i = 0; i < rows; ++i) {
    sample.flags = {};
    sample.has_temperature = temp != nullptr;
    sample.temperature_mdegc =
        temp != nullptr
            ? static_cast<std::int32_t>(std::lround(std::clamp((*temp)[i], -1e6, 1e6) * 1000.0))
            : 0;
    for (std::size_t c = 0; c < n; ++c) {
      sample.counts[c] = InputCounts((*b[c])[i], counts_per_input, rails);
      if (hal::NearRail(sample.counts[c], rails)) sample.flags[c] |= hal::kChannelSaturated;
    }
    core.Process(sample, false, o);
    out[0][i] = has_t ? in.Column("t")[i] : static_cast<double>(i);
    for (std::size_t r = 0; r < 6; ++r) out[r + 1][i] = o.wrench[r] * fw::AxisLsb(r);
    status[i] = o.status;
  }
  Recording rec;
  rec.path = "(applied)";
  rec.metadata.push_back("calibration: " + cal.serial);
  rec.names = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "status"};
  rec.columns = std::move(out);
  rec.columns.push_back(std::move(status));
  return rec;
}

}  // namespace ftstack::cal
