#include "calibration/fit/input_units.hpp"

#include <cstdio>

namespace ftstack::cal {
namespace {

std::string ConverterWhat(const Converter& c) {
  return "the range of the " + std::to_string(c.bits) + "-bit " + ToString(c.coding) + " converter";
}

}  // namespace

FitInput PrepareFitInput(Recording* rec, const UnitOverrides& cli, const hal::AdcInfo& assumed) {
  FitInput in;
  in.declared = ResolveInputUnit(*rec, cli);
  const std::size_t n = rec->BridgeCount();
  const InputUnit& u = in.declared;
  InputMap map;
  std::string what;
  if (u.has_converter) {
    in.adc = AdcOfConverter(u.converter, u.excitation_v, n, &in.cal_unit);
    what = ConverterWhat(u.converter);
  } else {
    in.adc = assumed;
    in.adc.channel_count = static_cast<std::uint8_t>(n);
    in.cal_unit = "mV/V";
    char full_scale[32];
    std::snprintf(full_scale, sizeof full_scale, "%.6g",
                  static_cast<double>(assumed.full_scale_nvv) * 1e-6);
    what = std::string("the range of the assumed converter (±") + full_scale + " mV/V)";
  }
  if (u.unit == BridgeUnit::kVolts) map.scale = 1000.0 / u.excitation_v;
  if (u.unit == BridgeUnit::kCounts) {
    map.zero = static_cast<double>(ZeroCode(u.converter));
    if (in.cal_unit == "mV/V") map.scale = MvvPerCount(u.converter, u.excitation_v);
  }
  CheckMappedRails(*rec, n, in.adc, map, ToString(u.unit), what);
  ApplyInputMap(rec, n, map);
  in.description = Describe(u) + "; fitted in " + in.cal_unit;
  return in;
}

void RecordInputUnit(const FitInput& in, CalFile* file) {
  file->input_unit = in.cal_unit;
  if (in.declared.has_converter) {
    file->extra["converter"] = FormatConverter(in.declared.converter);
  }
  file->extra["recording_unit"] = ToString(in.declared.unit);
  if (in.declared.excitation_v > 0) file->extra["excitation_v"] = in.declared.excitation_v;
}

}  // namespace ftstack::cal
