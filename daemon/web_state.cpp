#include "daemon/web_state.hpp"

#include <cmath>
#include <string>

#include "firmware/health_registers.hpp"
#include "firmware/health_types.hpp"
#include "firmware/register_map.hpp"

namespace ftstack::daemon {

namespace {

constexpr const char* kAxisNames[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};

/// Status bit names (input register 1), bit 0 first; "" for a bit the map does not use.
constexpr const char* kStatusWords[16] = {"saturated",
                                          "overload",
                                          "bridge fault",
                                          "ADC fault",
                                          "calibration invalid",
                                          "tare active",
                                          "temperature out of range",
                                          "simulated",
                                          "stale",
                                          "late sample",
                                          "axis invalid",
                                          "",
                                          "payload compensated",
                                          "",
                                          "",
                                          ""};

constexpr const char* kNe107[5] = {"normal", "failure", "check function", "out of specification",
                                   "maintenance required"};

/// Per cause (1 … 8): its name in the effect vocabulary, words, and what to do about it.
struct CauseText {
  const char* code;
  const char* words;
  const char* action;
};
constexpr CauseText kCauses[fw::kHealthCauses + 1] = {
    {"none", "", ""},
    {"zero_drift", "zero drift since the tare", "re-tare unloaded; check the mounting bolts"},
    {"thermal_zero_drift", "zero drift with temperature",
     "re-tare at the working temperature; shield the sensor from heat sources"},
    {"mains_50hz", "mains pick-up at 50 Hz",
     "check the cable shield and grounding; raise the low-pass (holding 1)"},
    {"mains_60hz", "mains pick-up at 60 Hz",
     "check the cable shield and grounding; raise the low-pass (holding 1)"},
    {"noise_floor", "noise above the commissioning's",
     "check the cable, connectors and excitation supply"},
    {"resonance_shift", "mount resonance moved", "check the mounting and the tool for loose parts"},
    {"creep", "creep in holds", "wait for readings to settle after load changes; re-calibrate"},
    {"overload_shift", "zero jumped across an overload",
     "inspect for damage; re-calibrate before trusting the readings"},
};

constexpr const char* kTareSources[6] = {"", "modbus", "rdt", "mqtt", "web", "opcua"};

double F(const std::uint16_t* r) { return static_cast<double>(fw::UnpackFloat32(r)); }
/// A float register pair as JSON: NaN (no value) becomes null.
nlohmann::json FJ(const std::uint16_t* r) {
  const double v = F(r);
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
nlohmann::json Six(const std::uint16_t* r) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) a.push_back(FJ(r + 2 * i));
  return a;
}

nlohmann::json StatusJson(std::uint16_t status) {
  nlohmann::json words = nlohmann::json::array();
  for (int b = 0; b < 16; ++b) {
    if ((status >> b & 1u) != 0) {
      words.push_back(kStatusWords[b][0] != 0 ? kStatusWords[b] : "bit " + std::to_string(b));
    }
  }
  return {{"bits", status}, {"words", words}};
}

nlohmann::json HealthJson(const std::uint16_t* in) {
  const std::uint16_t state = in[fw::kInHealthState];
  nlohmann::json findings = nlohmann::json::array();
  for (std::size_t k = 0; k < fw::kHealthSlots; ++k) {
    const std::uint16_t cause = in[fw::kInFindingCause + k];
    if (cause == 0 || cause > fw::kHealthCauses) continue;
    findings.push_back({{"cause", cause},
                        {"code", kCauses[cause].code},
                        {"words", kCauses[cause].words},
                        {"action", kCauses[cause].action},
                        {"error_n_nm", Six(in + fw::kInFindingError + 12 * k)}});
  }
  // Coverage (input 196) tells "no finding" from "could not look" for each cause.
  nlohmann::json coverage = nlohmann::json::array();
  const std::uint16_t judged = in[fw::kInCoverage];
  for (std::uint16_t cause = 1; cause <= fw::kHealthCauses; ++cause) {
    coverage.push_back({{"cause", cause},
                        {"code", kCauses[cause].code},
                        {"words", kCauses[cause].words},
                        {"judged_last_hour", (judged >> (cause - 1) & 1u) != 0}});
  }
  const std::uint16_t reason = in[fw::kInRetareReason];
  return {{"watch_on", in[fw::kInHealthWatchOn] != 0},
          {"ne107", state},
          {"ne107_words", state < 5 ? kNe107[state] : "unknown"},
          {"findings", findings},
          {"coverage_bits", judged},
          {"coverage", coverage},
          {"retare_suggested", in[fw::kInRetareSuggested] != 0},
          {"retare_reason", reason <= fw::kHealthCauses ? kCauses[reason].code : "unknown"}};
}

}  // namespace

nlohmann::json LiveFromRegisters(const std::uint16_t* in) {
  nlohmann::json mn = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) mn.push_back(fw::UnpackI32(in + fw::kInWrenchInt + 2 * i));
  return {{"sequence", fw::UnpackU32(in + fw::kInSequence)},
          {"timestamp_us", fw::UnpackU32(in + fw::kInTimestampUs)},
          {"status", StatusJson(in[fw::kInStatus])},
          {"wrench_n_nm", Six(in + fw::kInWrenchFloat)},
          {"wrench_mn_mnm", mn},
          {"temperature_c", FJ(in + fw::kInTemperature)},
          {"health", HealthJson(in)}};
}

nlohmann::json StateFromRegisters(const std::uint16_t* in, const std::uint16_t* hold,
                                  const WebStaticInfo& info) {
  nlohmann::json s = LiveFromRegisters(in);
  s["map_version"] = in[fw::kInMapVersion];
  s["bridge_mvv"] = Six(in + fw::kInBridgeMvv);
  s["overload"] = {{"events", fw::UnpackU32(in + fw::kInOverloadEvents)},
                   {"peaks_n_nm", Six(in + fw::kInPeaks)}};
  const std::uint16_t slot = in[fw::kInCalSlot];
  nlohmann::json cal = {{"slot", slot},
                        {"slot_name", slot == 0 ? "A" : "B"},
                        {"crc32", fw::UnpackU32(in + fw::kInCalCrc)}};
  if (slot < 2 && info.slots[slot].present) {
    cal["serial"] = info.slots[slot].serial;
    cal["date"] = info.slots[slot].date;
    cal["file"] = info.slots[slot].file;
  }
  s["calibration"] = cal;
  s["late_samples"] = fw::UnpackU32(in + fw::kInLateSamples);
  s["payload"] = {{"mass_kg", FJ(in + fw::kInPayloadMass)},
                  {"crc32", fw::UnpackU32(in + fw::kInPayloadCrc)},
                  {"compensation_on", hold[fw::kHoldGravityComp] != 0},
                  {"gravity_mps2",
                   {FJ(hold + fw::kHoldGravity), FJ(hold + fw::kHoldGravity + 2),
                    FJ(hold + fw::kHoldGravity + 4)}}};
  s["tool_transform"] = {{"translation_m", nlohmann::json::array()},
                         {"rotation_deg", nlohmann::json::array()}};
  s["mount_transform"] = {{"translation_m", nlohmann::json::array()},
                          {"rotation_deg", nlohmann::json::array()}};
  for (int i = 0; i < 3; ++i) {
    s["tool_transform"]["translation_m"].push_back(FJ(hold + fw::kHoldTransform + 2 * i));
    s["tool_transform"]["rotation_deg"].push_back(FJ(hold + fw::kHoldTransform + 6 + 2 * i));
    s["mount_transform"]["translation_m"].push_back(FJ(hold + fw::kHoldMount + 2 * i));
    s["mount_transform"]["rotation_deg"].push_back(FJ(hold + fw::kHoldMount + 6 + 2 * i));
  }
  nlohmann::json thresholds = nlohmann::json::array();
  for (std::uint16_t a = fw::kHoldHealthFirstThreshold; a <= fw::kHoldHealthLastThreshold; ++a) {
    thresholds.push_back(hold[a]);
  }
  s["settings"] = {{"filter_length", hold[fw::kHoldFilterLength]},
                   {"decimation", hold[fw::kHoldDecimation]},
                   {"health_thresholds_51_59", thresholds}};
  // Health figures.
  nlohmann::json& h = s["health"];
  h["zero_drift_n_nm"] = Six(in + fw::kInZeroDrift);
  h["thermal_zero_pct_per_k"] = FJ(in + fw::kInThermalZero);
  h["mains_50hz_pct"] = FJ(in + fw::kInMains50);
  h["mains_60hz_pct"] = FJ(in + fw::kInMains60);
  h["noise_ratio"] = FJ(in + fw::kInNoiseRatio);
  h["ring_hz"] = FJ(in + fw::kInRingHz);
  h["ring_ref_hz"] = FJ(in + fw::kInRingRefHz);
  h["creep_pct"] = FJ(in + fw::kInCreepPct);
  h["zero_points"] = fw::UnpackU32(in + fw::kInZeroPoints);
  h["tare_age_s"] = fw::UnpackU32(in + fw::kInTareAge);
  h["tare_temperature_c"] = FJ(in + fw::kInTareTemp);
  h["tare_count"] = in[fw::kInTareCount];
  nlohmann::json cycles = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) cycles.push_back(in[fw::kInCycles + i]);
  h["cycles_over_10pct"] = cycles;
  // Tare history, newest first; empty slots left out.
  nlohmann::json tares = nlohmann::json::array();
  for (std::size_t k = 0; k < fw::kTareHistory; ++k) {
    const std::uint16_t* r = in + fw::kInTareHistory + k * fw::kTareRecordRegisters;
    const std::uint32_t number = fw::UnpackU32(r);
    if (number == 0) continue;
    const std::uint16_t src = r[2];
    tares.push_back({{"number", number},
                     {"source", src < 6 ? kTareSources[src] : "unknown"},
                     {"time_s", fw::UnpackU32(r + 4)},
                     {"temperature_c", FJ(r + 6)},
                     {"load_n_nm", Six(r + 8)}});
  }
  s["tare_history"] = tares;
  // Rainflow bins per axis.
  nlohmann::json bins = nlohmann::json::object();
  for (std::size_t a = 0; a < 6; ++a) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t b = 0; b < fw::kRainflowBins; ++b) {
      row.push_back(fw::UnpackU32(in + fw::kInCycleBins + 2 * (a * fw::kRainflowBins + b)));
    }
    bins[kAxisNames[a]] = row;
  }
  nlohmann::json edges = nlohmann::json::array();
  for (const std::int32_t e : fw::kRainflowBinEdgesPct) edges.push_back(e);
  s["rainflow"] = {{"bin_upper_edges_pct_of_rated", edges}, {"cycles", bins}};
  s["mqtt"] = {{"connected", in[fw::kInMqttConnected] != 0},
               {"published", fw::UnpackU32(in + fw::kInMqttPublished)},
               {"dropped", fw::UnpackU32(in + fw::kInMqttDropped)},
               {"reconnects", fw::UnpackU32(in + fw::kInMqttReconnects)}};
  return s;
}

}  // namespace ftstack::daemon
