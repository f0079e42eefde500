#include "calibration/file/recorded_unit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "firmware/fixed_calibration.hpp"

namespace ftstack::cal {
namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// Where a recording's unit was declared: "--converter/--bridge-unit" or FILE:LINE of the first
/// unit metadata line (metadata lines open the file, one a line).
std::string DeclarationPlace(const Recording& rec, const UnitOverrides& cli) {
  if (!cli.unit.empty() || !cli.converter.empty()) return "--bridge-unit/--converter";
  for (std::size_t i = 0; i < rec.metadata.size(); ++i) {
    const std::string& m = rec.metadata[i];
    for (const char* key : {"bridge_unit:", "converter:", "excitation_v:"}) {
      if (m.rfind(key, 0) == 0) return rec.path + ":" + std::to_string(i + 1);
    }
  }
  return rec.path;
}

/// Refuses (FILE:LINE:COLUMN) a code that is not a whole number: not a count of any converter.
void CheckWholeCodes(const Recording& rec, std::size_t channels, const Converter& c) {
  for (std::size_t ch = 0; ch < channels; ++ch) {
    const std::string name = "b" + std::to_string(ch);
    const std::vector<double>& col = rec.Column(name);
    for (std::size_t i = 0; i < col.size(); ++i) {
      if (col[i] == std::nearbyint(col[i])) continue;
      const std::size_t line = i < rec.data_lines.size() ? rec.data_lines[i] : i + 2;
      throw RecordingError(
          rec.path + ":" + std::to_string(line) + ":" +
          std::to_string(FieldColumn(rec, line, static_cast<std::size_t>(rec.Find(name)))) + ": " +
          name + " = " + Num(col[i]) + " is not a whole code of the " + std::to_string(c.bits) +
          "-bit " + ToString(c.coding) + " converter: not counts");
    }
  }
}

}  // namespace

void CheckMappedRails(const Recording& rec, std::size_t channels, const hal::AdcInfo& adc,
                      const InputMap& map, const std::string& unit, const std::string& what) {
  const double units_per_count = 1.0 / fw::CountsPerMvv(adc);
  ValueRange r;
  const double lo = adc.min_counts * units_per_count;
  const double hi = adc.max_counts * units_per_count;
  r.min = std::fmin(lo / map.scale + map.zero, hi / map.scale + map.zero);
  r.max = std::fmax(lo / map.scale + map.zero, hi / map.scale + map.zero);
  r.unit = unit;
  r.what = what;
  CheckBridgeRange(rec, channels, r, 0.5 * units_per_count / std::fabs(map.scale));
}

hal::AdcInfo AdcOfConverter(const Converter& c, double excitation_v, std::size_t channels,
                            std::string* unit) {
  hal::AdcInfo a;
  a.channel_count = static_cast<std::uint8_t>(channels);
  a.min_counts = static_cast<std::int32_t>(MinCode(c) - ZeroCode(c));
  a.max_counts = static_cast<std::int32_t>(MaxCode(c) - ZeroCode(c));
  const double mvv = MvvPerCount(c, excitation_v);
  *unit = mvv > 0 ? "mV/V" : "counts";
  const double per_count = mvv > 0 ? mvv : 1.0;
  a.full_scale_nvv = std::llround(a.max_counts * per_count * 1e6);
  return a;
}

void ApplyInputMap(Recording* rec, std::size_t channels, const InputMap& map) {
  if (map.scale == 1.0 && map.zero == 0.0) return;
  for (std::size_t c = 0; c < channels; ++c) {
    for (double& x : rec->Column("b" + std::to_string(c))) x = (x - map.zero) * map.scale;
  }
}

std::string PrepareApplyInput(Recording* rec, const UnitOverrides& cli, const CalFile& cal,
                              const std::string& cal_path) {
  const InputUnit u = UnitForCalibration(*rec, cli, cal, cal_path);
  // Too few bridge columns: ApplyCalibration says so.
  const std::size_t n = std::min<std::size_t>(cal.cal.channel_count, rec->BridgeCount());
  InputMap map;
  const std::string& cu = cal.input_unit;
  auto refuse = [&](const std::string& why) {
    throw RecordingError(rec->path + ": " + why + " (calibration input unit " + cu +
                         "); declare the unit (# bridge_unit:, # converter:, or --bridge-unit/"
                         "--converter)");
  };
  if (cu == "counts") {
    if (u.unit != BridgeUnit::kCounts) refuse("bridge columns in " + std::string(ToString(u.unit)));
    hal::AdcInfo mine{};
    std::string unit;
    mine = AdcOfConverter(u.converter, u.excitation_v, n, &unit);
    if (mine.min_counts != cal.adc.min_counts || mine.max_counts != cal.adc.max_counts) {
      refuse("the recording's converter (" + FormatConverter(u.converter) +
             ") is not the calibration's");
    }
    map.zero = static_cast<double>(ZeroCode(u.converter));
  } else if (cu == "mV/V") {
    if (u.unit == BridgeUnit::kVolts) map.scale = 1000.0 / u.excitation_v;
    if (u.unit == BridgeUnit::kCounts) {
      map.zero = static_cast<double>(ZeroCode(u.converter));
      map.scale = MvvPerCount(u.converter, u.excitation_v);
      if (!(map.scale > 0)) refuse("the converter's counts have no known mV/V scale");
    }
  } else if (cu == "V") {
    if (u.unit == BridgeUnit::kMvv && u.excitation_v > 0)
      map.scale = u.excitation_v / 1000.0;
    else if (u.unit != BridgeUnit::kVolts)
      refuse("bridge columns not in V");
  } else {
    refuse("unknown calibration input unit");
  }
  if (u.unit == BridgeUnit::kCounts) CheckWholeCodes(*rec, n, u.converter);
  CheckMappedRails(*rec, n, cal.adc, map, ToString(u.unit),
                   "the range of the calibration's converter (" +
                       std::to_string(cal.adc.min_counts) + " … " +
                       std::to_string(cal.adc.max_counts) + " counts)");
  ApplyInputMap(rec, n, map);
  return Describe(u) + "; applied in " + cu;
}

InputUnit UnitForCalibration(const Recording& rec, const UnitOverrides& cli, const CalFile& cal,
                             const std::string& cal_path) {
  InputUnit u = ResolveInputUnit(rec, cli);
  const std::string fitted_unit = cal.extra.value("recording_unit", std::string());
  if (fitted_unit.empty()) return u;  // a file that does not say: the recording's own (or default)
  InputUnit fitted;
  try {
    fitted.unit = ParseBridgeUnit(fitted_unit);
    const std::string conv = cal.extra.value("converter", std::string());
    if (!conv.empty()) {
      fitted.converter = ParseConverter(conv, cal_path + ": converter");
      fitted.has_converter = true;
    }
  } catch (const std::invalid_argument& e) {
    throw CalFileError(cal_path + ": recording_unit/converter: " + e.what());
  }
  fitted.excitation_v = cal.extra.value("excitation_v", 0.0);
  fitted.source = "calibration " + cal_path;
  if (u.source == "format default") {
    if (fitted.unit == BridgeUnit::kVolts && !(fitted.excitation_v > 0)) return u;
    return fitted;
  }
  const bool same_converter = !fitted.has_converter || !u.has_converter ||
                              FormatConverter(fitted.converter) == FormatConverter(u.converter);
  if (u.unit != fitted.unit || (fitted.unit == BridgeUnit::kCounts && !same_converter)) {
    const std::string declared =
        std::string(ToString(u.unit)) +
        (u.has_converter ? " of converter (" + FormatConverter(u.converter) + ")" : "");
    const std::string wanted =
        std::string(ToString(fitted.unit)) +
        (fitted.has_converter ? " of converter (" + FormatConverter(fitted.converter) + ")" : "");
    throw RecordingError(DeclarationPlace(rec, cli) + ": declares bridge unit " + declared +
                         ", but " + cal_path + " was fitted from " + wanted +
                         ": refused (drop the declaration to use the calibration's)");
  }
  if (u.excitation_v <= 0) u.excitation_v = fitted.excitation_v;
  return u;
}

std::int32_t InputCounts(double value, double counts_per_input, const hal::AdcInfo& adc) {
  const double v = std::nearbyint(value * counts_per_input);
  if (!(v < adc.max_counts)) return adc.max_counts;  // NaN too: never a value read as true
  if (v < adc.min_counts) return adc.min_counts;
  return static_cast<std::int32_t>(v);
}

}  // namespace ftstack::cal
