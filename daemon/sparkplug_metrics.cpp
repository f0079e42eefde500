#include "daemon/sparkplug_metrics.hpp"

#include <unordered_map>

#include "firmware/status_bits.hpp"
#include "firmware/wrench.hpp"

namespace ftstack::daemon {

using sparkplug::Bool;
using sparkplug::DataType;
using sparkplug::Metric;
using sparkplug::Real;
using sparkplug::Text;
using sparkplug::UInt;

namespace {

constexpr const char* kAxisMetric[6] = {"Fx_n", "Fy_n", "Fz_n", "Mx_nm", "My_nm", "Mz_nm"};

struct StatusName {
  std::uint16_t bit;
  const char* name;
};
constexpr StatusName kStatusNames[] = {
    {fw::kStatusSaturated, "Saturated"},
    {fw::kStatusOverload, "Overload"},
    {fw::kStatusBridgeFault, "Bridge Fault"},
    {fw::kStatusAdcFault, "ADC Fault"},
    {fw::kStatusCalInvalid, "Calibration Invalid"},
    {fw::kStatusTareActive, "Tare Active"},
    {fw::kStatusTempRange, "Temperature Range"},
    {fw::kStatusSimulated, "Simulated"},
    {fw::kStatusStale, "Stale"},
    {fw::kStatusLate, "Late"},
    {fw::kStatusAxisInvalid, "Axis Invalid"},
    {fw::kStatusPayloadComp, "Payload Compensation"},
};

}  // namespace

std::vector<Metric> WrenchMetrics(const WrenchWindow& w, std::int64_t utc_offset_us) {
  std::vector<Metric> m;
  m.reserve(9);
  for (std::size_t i = 0; i < 6; ++i) {
    const bool invalid = w.samples == 0 || (w.invalid_axes & (1u << i)) != 0 ||
                         (w.status_or & fw::kStatusCalInvalid) != 0;
    const double mean =
        invalid ? 0.0 : static_cast<double>(w.sum_lsb[i]) / w.samples * fw::AxisLsb(i);
    m.push_back(Real(std::string("Wrench/") + kAxisMetric[i], DataType::kDouble, mean, invalid));
  }
  m.push_back(UInt("Wrench/Samples", DataType::kUInt32, w.samples));
  m.push_back(UInt("Wrench/Sequence", DataType::kUInt32, w.last_sequence));
  m.push_back(
      UInt("Wrench/Time_us", DataType::kUInt64,
           static_cast<std::uint64_t>(static_cast<std::int64_t>(w.end_us) + utc_offset_us)));
  return m;
}

std::vector<Metric> ExceptionMetrics(const DeviceState& s) {
  const fw::DeviceSample& d = s.latest;
  std::vector<Metric> m;
  m.push_back(UInt("Status/Bits", DataType::kUInt16, d.sample.status));
  for (const StatusName& n : kStatusNames) {
    m.push_back(Bool(std::string("Status/") + n.name, (d.sample.status & n.bit) != 0));
  }
  m.push_back(UInt("Events/Overload Events", DataType::kUInt32, d.overload_events));
  m.push_back(UInt("Events/Late Samples", DataType::kUInt32, d.late_samples));
  // The health watch (input 100, 101, 196): NE 107 state, findings and coverage, bit (cause − 1).
  m.push_back(UInt("Health/State", DataType::kUInt8, static_cast<std::uint64_t>(d.health.state)));
  m.push_back(UInt("Health/Findings", DataType::kUInt16, d.health.findings));
  m.push_back(UInt("Health/Coverage", DataType::kUInt16, d.health.coverage));
  for (std::size_t i = 0; i < 6; ++i) {
    const bool invalid = (d.peaks_invalid_axes & (1u << i)) != 0;
    m.push_back(Real(std::string("Peaks/") + kAxisMetric[i], DataType::kDouble,
                     d.peaks_lsb[i] * fw::AxisLsb(i), invalid));
  }
  m.push_back(UInt("Config/Calibration CRC", DataType::kUInt32, d.cal_crc));
  m.push_back(UInt("Config/Calibration Slot", DataType::kUInt8, d.cal_slot));
  m.push_back(UInt("Config/Payload CRC", DataType::kUInt32, d.payload_crc));
  m.push_back(Real("Config/Payload Mass_kg", DataType::kDouble,
                   static_cast<double>(d.payload_mass_ug) * 1e-9));
  constexpr const char* kTransform[6] = {"Dx_m", "Dy_m", "Dz_m", "Rx_deg", "Ry_deg", "Rz_deg"};
  for (std::size_t i = 0; i < 6; ++i) {
    m.push_back(Real(std::string("Config/Tool Transform/") + kTransform[i], DataType::kFloat,
                     s.transform[i]));
  }
  m.push_back(UInt("Config/Filter Length", DataType::kUInt16, s.filter_length));
  m.push_back(UInt("Config/Decimation", DataType::kUInt16, s.decimation));
  m.push_back(Bool("Config/Gravity Compensation", s.gravity_comp));
  m.push_back(UInt("MQTT/Dropped", DataType::kUInt64, s.mqtt_dropped));
  m.push_back(UInt("MQTT/Reconnects", DataType::kUInt32, s.mqtt_reconnects));
  m.push_back(Bool("Device Control/Write Protected", s.write_protected));
  m.push_back(UInt("Device Control/Commands", DataType::kUInt32, s.commands));
  m.push_back(Text("Device Control/Last Command", s.last_command));
  m.push_back(Text("Device Control/Last Result", s.last_result));
  return m;
}

std::vector<Metric> CommandMetrics() {
  return {Bool("Device Control/Tare", false), Bool("Device Control/Clear Peaks", false)};
}

std::vector<Metric> Changed(const std::vector<Metric>& now, const std::vector<Metric>& sent) {
  std::unordered_map<std::string, const Metric*> before;
  for (const Metric& m : sent) before[m.name] = &m;
  // A command's acknowledgement is the counter with its name and result, even when those two
  // repeat the previous command's.
  const auto changed = [&](const std::string& name) {
    const auto it = before.find(name);
    for (const Metric& m : now) {
      if (m.name == name) return it == before.end() || !(*it->second == m);
    }
    return false;
  };
  const bool acknowledge = changed("Device Control/Commands");
  std::vector<Metric> out;
  for (const Metric& m : now) {
    const bool ack = acknowledge && m.name.rfind("Device Control/Last ", 0) == 0;
    const auto it = before.find(m.name);
    if (ack || it == before.end() || !(*it->second == m)) out.push_back(m);
  }
  return out;
}

}  // namespace ftstack::daemon
