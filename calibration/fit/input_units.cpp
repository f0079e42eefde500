#include "calibration/fit/input_units.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "firmware/fixed_calibration.hpp"

namespace ftstack::cal {
namespace {

/// x_cal = (x − zero) · scale.
struct Affine {
  double scale = 1.0;
  double zero = 0.0;
};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string ConverterWhat(const Converter& c) {
  return "the range of the " + std::to_string(c.bits) + "-bit " + ToString(c.coding) + " converter";
}

/// Refuses values of `rec` outside cal-unit rails [lo, hi] (given through `map`).
void CheckRails(const Recording& rec, std::size_t channels, const hal::AdcInfo& adc,
                double units_per_count, const Affine& map, const std::string& unit,
                const std::string& what) {
  ValueRange r;
  const double lo = adc.min_counts * units_per_count;
  const double hi = adc.max_counts * units_per_count;
  r.min = std::fmin(lo / map.scale + map.zero, hi / map.scale + map.zero);
  r.max = std::fmax(lo / map.scale + map.zero, hi / map.scale + map.zero);
  r.unit = unit;
  r.what = what;
  CheckBridgeRange(rec, channels, r, 0.5 * units_per_count / std::fabs(map.scale));
}

void ApplyMap(Recording* rec, std::size_t channels, const Affine& map) {
  if (map.scale == 1.0 && map.zero == 0.0) return;
  for (std::size_t c = 0; c < channels; ++c) {
    for (double& x : rec->Column("b" + std::to_string(c))) x = (x - map.zero) * map.scale;
  }
}

}  // namespace

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

FitInput PrepareFitInput(Recording* rec, const UnitOverrides& cli, const hal::AdcInfo& assumed) {
  FitInput in;
  in.declared = ResolveInputUnit(*rec, cli);
  const std::size_t n = rec->BridgeCount();
  const InputUnit& u = in.declared;
  Affine map;
  std::string what;
  if (u.has_converter) {
    in.adc = AdcOfConverter(u.converter, u.excitation_v, n, &in.cal_unit);
    what = ConverterWhat(u.converter);
  } else {
    in.adc = assumed;
    in.adc.channel_count = static_cast<std::uint8_t>(n);
    in.cal_unit = "mV/V";
    what = "the range of the assumed converter (±" +
           Num(static_cast<double>(assumed.full_scale_nvv) * 1e-6) + " mV/V)";
  }
  if (u.unit == BridgeUnit::kVolts) map.scale = 1000.0 / u.excitation_v;
  if (u.unit == BridgeUnit::kCounts) {
    map.zero = static_cast<double>(ZeroCode(u.converter));
    if (in.cal_unit == "mV/V") map.scale = MvvPerCount(u.converter, u.excitation_v);
  }
  const double per_count = 1.0 / fw::CountsPerMvv(in.adc);
  CheckRails(*rec, n, in.adc, per_count, map, ToString(u.unit), what);
  ApplyMap(rec, n, map);
  in.description = Describe(u) + "; fitted in " + in.cal_unit;
  return in;
}

std::string PrepareApplyInput(Recording* rec, const UnitOverrides& cli, const CalFile& cal) {
  const InputUnit u = ResolveInputUnit(*rec, cli);
  // Too few bridge columns: ApplyCalibration says so.
  const std::size_t n = std::min<std::size_t>(cal.cal.channel_count, rec->BridgeCount());
  Affine map;
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
  const double per_count = 1.0 / fw::CountsPerMvv(cal.adc);
  CheckRails(*rec, n, cal.adc, per_count, map, ToString(u.unit),
             "the range of the calibration's converter (" + std::to_string(cal.adc.min_counts) +
                 " … " + std::to_string(cal.adc.max_counts) + " counts)");
  ApplyMap(rec, n, map);
  return Describe(u) + "; applied in " + cu;
}

void RecordInputUnit(const FitInput& in, CalFile* file) {
  file->input_unit = in.cal_unit;
  if (in.declared.has_converter) {
    file->extra["converter"] = FormatConverter(in.declared.converter);
  }
  file->extra["recording_unit"] = ToString(in.declared.unit);
}

}  // namespace ftstack::cal
