// The register map three ways — docs/spec/modbus-map.md, docs/spec/modbus-map.csv and the
// firmware's RegisterMap — held to each other: addresses, types, tags, units, scaling, access and
// ranges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/register_map.hpp"
#include "tests/firmware/register_map_fixture.hpp"

namespace ftstack::fw {
namespace {

using maptest::g_now_us;
using maptest::kGain;
using maptest::kMvvPerCount;

/// One tag of the map (one row of the CSV; one element of a block row of the markdown table).
struct Tag {
  std::string table;  ///< "input" or "holding"
  int address = -1;
  int registers = 0;
  std::string type, tag, unit, scale, access, min, max, description;
  bool operator==(const Tag&) const = default;
};

std::string ReadText(const std::string& rel) {
  std::ifstream in(std::string(FTSTACK_SOURCE_DIR) + "/" + rel, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

/// Parses the CSV; problems (bad header, wrong field count) go to *errors with the line number.
std::vector<Tag> ParseCsv(const std::string& text, std::vector<std::string>* errors) {
  std::vector<Tag> tags;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (n == 1) {
      if (line != "table,address,registers,type,tag,unit,scale,access,min,max,description") {
        errors->push_back("csv:1: unexpected header");
      }
      continue;
    }
    if (line.empty()) continue;
    const auto f = SplitCsvLine(line);
    if (f.size() != 11) {
      errors->push_back("csv:" + std::to_string(n) + ": " + std::to_string(f.size()) + " fields");
      continue;
    }
    tags.push_back({f[0], std::atoi(f[1].c_str()), std::atoi(f[2].c_str()), f[3], f[4], f[5], f[6],
                    f[7], f[8], f[9], f[10]});
  }
  return tags;
}

std::vector<std::string> Words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> w;
  for (std::string x; in >> x;) w.push_back(x);
  return w;
}

std::string Trim(const std::string& s) {
  const auto a = s.find_first_not_of(' ');
  const auto b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

int RegistersOf(const std::string& type) { return type == "uint16" ? 1 : 2; }

/// Expands the markdown table that follows `heading` into tags: "6–17 | float32 ×6 | Fx_n … |".
std::vector<Tag> ParseMarkdownTable(const std::string& md, const std::string& heading,
                                    const std::string& table, std::vector<std::string>* errors) {
  std::vector<Tag> tags;
  const auto at = md.find(heading);
  if (at == std::string::npos) {
    errors->push_back("md: no section '" + heading + "'");
    return tags;
  }
  std::istringstream in(md.substr(at));
  std::string line;
  int row = 0;
  bool started = false;
  while (std::getline(in, line)) {
    if (line.rfind('|', 0) != 0) {
      if (started) break;
      continue;
    }
    started = true;
    if (++row <= 2) continue;  // header and separator
    std::vector<std::string> c;
    std::string cell;
    for (std::size_t i = 1; i < line.size(); ++i) {
      if (line[i] == '|') {
        c.push_back(Trim(cell));
        cell.clear();
      } else {
        cell += line[i];
      }
    }
    const bool holding = table == "holding";
    if (c.size() != (holding ? 9u : 6u)) {
      errors->push_back("md " + table + " row " + std::to_string(row) + ": " +
                        std::to_string(c.size()) + " cells");
      continue;
    }
    const std::string type = Words(c[1]).empty() ? "" : Words(c[1])[0];
    const auto names = Words(c[2]);
    auto units = Words(c[3]);
    if (units.empty()) units.assign(names.size(), "");
    if (units.size() != names.size()) {
      errors->push_back("md " + table + " row " + std::to_string(row) + ": tags and units differ");
      continue;
    }
    const int first = std::atoi(c[0].c_str());
    for (std::size_t i = 0; i < names.size(); ++i) {
      Tag t{table,
            first + static_cast<int>(i) * RegistersOf(type),
            RegistersOf(type),
            type,
            names[i],
            units[i],
            c[4],
            holding ? c[5] : "r",
            holding ? c[6] : "",
            holding ? c[7] : "",
            holding ? c[8] : c[5]};
      tags.push_back(t);
    }
    // The address column spans exactly the block ("6–17" for six float32).
    const auto dash = c[0].find("–");
    const int last = dash == std::string::npos ? first : std::atoi(c[0].c_str() + dash + 3);
    const int want_last = first + static_cast<int>(names.size()) * RegistersOf(type) - 1;
    if (last != want_last) {
      errors->push_back("md " + table + " row " + std::to_string(row) + ": address range " + c[0] +
                        " does not match its " + std::to_string(names.size()) + " " + type);
    }
  }
  return tags;
}

std::vector<Tag> ParseMarkdown(const std::string& md, std::vector<std::string>* errors) {
  auto tags = ParseMarkdownTable(md, "## Input registers", "input", errors);
  const auto holding = ParseMarkdownTable(md, "## Holding registers", "holding", errors);
  tags.insert(tags.end(), holding.begin(), holding.end());
  return tags;
}

std::string Describe(const Tag& t) {
  return t.table + " " + std::to_string(t.address) + " " + t.type + " " + t.tag + " [" + t.unit +
         "] ×" + t.scale + " " + t.access + " " + t.min + "…" + t.max;
}

/// Differences between the markdown's tags and the CSV's, one line each.
std::vector<std::string> CompareTables(const std::vector<Tag>& md, const std::vector<Tag>& csv) {
  std::vector<std::string> diffs;
  if (md.size() != csv.size()) {
    diffs.push_back("md has " + std::to_string(md.size()) + " tags, csv " +
                    std::to_string(csv.size()));
  }
  for (std::size_t i = 0; i < std::min(md.size(), csv.size()); ++i) {
    if (!(md[i] == csv[i]))
      diffs.push_back("md: " + Describe(md[i]) + " | csv: " + Describe(csv[i]));
  }
  return diffs;
}

/// What each unit means after `scale`, and the tag suffix that names it (the project's naming
/// rule).
struct UnitRule {
  std::string unit, suffix, scaled_unit;
};
const std::vector<UnitRule>& UnitRules() {
  static const std::vector<UnitRule> rules = {{"N", "_n", "N"},
                                              {"N·m", "_nm", "N·m"},
                                              {"mN", "_mn", "N"},
                                              {"mN·m", "_mnm", "N·m"},
                                              {"counts", "_counts", "counts"},
                                              {"mV/V", "_mvv", "mV/V"},
                                              {"µs", "_us", "s"},
                                              {"°C", "_c", "°C"},
                                              {"m", "_m", "m"},
                                              {"deg", "_deg", "deg"},
                                              {"kg", "_kg", "kg"},
                                              {"m/s²", "_mps2", "m/s²"},
                                              {"samples", "", "samples"},
                                              {"%", "_pct", "%"},
                                              {"%/K", "_pct_per_k", "%/K"},
                                              {"Hz", "_hz", "Hz"},
                                              {"s", "_s", "s"},
                                              {"", "", ""}};
  return rules;
}

/// The reference: the value each input tag must carry, in its scaled unit, for the sample the
/// fixture produces from `counts` (computed here from the calibration, not read from the code).
struct Expected {
  double value;
  double tol;
  std::string type;
};
std::map<std::string, Expected> ReferenceInputValues(
    const std::array<std::int32_t, hal::kMaxChannels>& counts, const LoadReport& report) {
  std::map<std::string, Expected> e;
  e["map_version"] = {3, 0, "uint16"};
  e["status"] = {0, 0, "uint16"};
  e["sequence"] = {3, 0, "uint32"};
  e["timestamp_us"] = {0.002, 1e-12, "uint32"};  // third sample at 1 kHz, in s after scaling
  const char* axes[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  for (std::size_t a = 0; a < 6; ++a) {
    const double si = kGain[a] * counts[a] * kMvvPerCount;
    const double tol = report.worst_case_error_si[a] + std::fabs(si) * 6e-8;
    const std::string u = a < 3 ? "_n" : "_nm";
    e[std::string(axes[a]) + u] = {si, tol, "float32"};
    e[std::string(axes[a]) + (a < 3 ? "_mn" : "_mnm")] = {si, tol + 0.5e-3, "int32"};
    e["peak_" + std::string(axes[a]) + u] = {std::fabs(si), tol, "float32"};
    const std::string b = "b" + std::to_string(a);
    e[b + "_counts"] = {static_cast<double>(counts[a]), 0, "int32"};
    e[b + "_mvv"] = {counts[a] * kMvvPerCount, std::fabs(counts[a] * kMvvPerCount) * 6e-8,
                     "float32"};
  }
  e["temperature_c"] = {20, 0, "float32"};
  e["bridge_count"] = {6, 0, "uint16"};
  e["cal_slot_active"] = {0, 0, "uint16"};
  e["overload_events"] = {0, 0, "uint32"};
  e["cal_crc32"] = {static_cast<double>(0xCAFEF00Du), 0, "uint32"};
  e["late_samples"] = {0, 0, "uint32"};
  e["timestamp_wraps"] = {0, 0, "uint16"};
  e["payload_mass_kg"] = {2.375, 2.375 * 6e-8, "float32"};  // the payload CodeCheck loads
  e["payload_crc32"] = {static_cast<double>(0x0BADC0DEu), 0, "uint32"};
  for (int a = 81; a <= 99; ++a) e["reserved_" + std::to_string(a)] = {0, 0, "uint16"};
  for (int a = 197; a <= 199; ++a) e["reserved_" + std::to_string(a)] = {0, 0, "uint16"};
  // The health watch three samples after start (the fixture has a rated range: it runs): normal,
  // nothing found, nothing measured yet.
  for (const char* tag :
       {"health_state", "health_findings", "retare_suggested", "retare_reason", "finding1_cause",
        "finding2_cause", "finding3_cause", "finding4_cause", "tare_count", "cycles_Fx",
        "cycles_Fy", "cycles_Fz", "cycles_Mx", "cycles_My", "cycles_Mz", "health_coverage"}) {
    e[tag] = {0, 0, "uint16"};
  }
  e["health_watch_on"] = {1, 0, "uint16"};
  for (const char* tag : {"zero_points", "tare_age_s"}) e[tag] = {0, 0, "uint32"};
  for (const char* tag : {"thermal_zero_pct_per_k", "mains50_pct", "mains60_pct", "noise_ratio",
                          "ring_hz", "ring_ref_hz", "creep_pct", "tare_temp_c"}) {
    e[tag] = {0, 0, "float32"};
  }
  for (std::size_t a = 0; a < 6; ++a) {
    const std::string axis = std::string(axes[a]) + (a < 3 ? "_n" : "_nm");
    e["zero_" + axis] = {0, 0, "float32"};
    for (int k = 1; k <= 4; ++k) {
      e["finding" + std::to_string(k) + "_err_" + axis] = {0, 0, "float32"};
    }
  }
  // The MQTT publisher's counters CodeCheck sets (map v3).
  e["mqtt_connected"] = {1, 0, "uint16"};
  e["mqtt_published"] = {4000000000.0, 0, "uint32"};
  e["mqtt_dropped"] = {17, 0, "uint32"};
  e["mqtt_reconnects"] = {3, 0, "uint32"};
  for (int a = 207; a <= 209; ++a) e["reserved_" + std::to_string(a)] = {0, 0, "uint16"};
  // The tare history before any tare: four empty slots, every register 0.
  for (int k = 1; k <= 4; ++k) {
    const std::string t = "tare" + std::to_string(k) + "_";
    e[t + "number"] = {0, 0, "uint32"};
    e[t + "source"] = {0, 0, "uint16"};
    e["reserved_" + std::to_string(210 + 20 * (k - 1) + 3)] = {0, 0, "uint16"};
    e[t + "time_s"] = {0, 0, "uint32"};
    e[t + "temp_c"] = {0, 0, "float32"};
    for (std::size_t a = 0; a < 6; ++a) {
      e[t + axes[a] + (a < 3 ? "_n" : "_nm")] = {0, 0, "float32"};
    }
  }
  // No rainflow cycle yet in any bin.
  for (std::size_t a = 0; a < 6; ++a) {
    for (int k = 1; k <= 8; ++k)
      e["rf_" + std::string(axes[a]) + "_b" + std::to_string(k)] = {0, 0, "uint32"};
  }
  return e;
}

double Decode(const std::string& type, const std::uint16_t* r) {
  if (type == "uint16") return r[0];
  if (type == "uint32") return UnpackU32(r);
  if (type == "int32") return UnpackI32(r);
  if (type == "float32") return UnpackFloat32(r);
  return std::nan("");
}

/// Runs the code's RegisterMap against the CSV's tags; one line per disagreement.
class CodeCheck : public maptest::RegisterMapTest {
 public:
  void TestBody() override {}
  std::vector<std::string> Run(const std::vector<Tag>& tags) {
    SetUp();
    cfg_.slots[1] = cfg_.slots[0];  // so that slot 1 can be selected
    // A payload, so that gravity compensation can be switched on (holding 28 = 1).
    if (MakeFixedPayload(2.375, {0.01, 0.02, 0.03}, {0, 0, 0}, {0, 0, 0}, &cfg_.payload) !=
        PayloadStatus::kOk) {
      return {"payload refused"};
    }
    cfg_.payload_crc = 0x0BADC0DEu;
    StartDevice();
    mqtt_.connected = 1;
    mqtt_.published = 4000000000u;
    mqtt_.dropped = 17;
    mqtt_.reconnects = 3;
    map_->SetMqttCounters(&mqtt_);
    adc_.counts = {400000, -300000, 1000000, 50000, -60000, 70000};
    Step(3);
    std::vector<std::string> d;
    CheckUnits(tags, &d);
    CheckInputLayout(tags, &d);
    CheckInputValues(tags, &d);
    CheckHoldingCoverage(tags, &d);
    for (const Tag& t : tags) {
      if (t.table == "holding") CheckHolding(t, &d);
    }
    return d;
  }

 private:
  MqttCounters mqtt_;

  static void CheckUnits(const std::vector<Tag>& tags, std::vector<std::string>* d) {
    for (const Tag& t : tags) {
      bool known = false;
      for (const UnitRule& r : UnitRules()) {
        if (r.unit != t.unit) continue;
        known = true;
        const bool suffix_ok =
            r.suffix.empty() || (t.tag.size() > r.suffix.size() && t.tag.ends_with(r.suffix));
        if (!suffix_ok) d->push_back(t.tag + ": name does not carry its unit " + t.unit);
      }
      if (!known) d->push_back(t.tag + ": unknown unit '" + t.unit + "'");
      if (RegistersOf(t.type) != t.registers) d->push_back(t.tag + ": " + t.type + " size");
      if (t.table == "input" && t.access != "r") d->push_back(t.tag + ": input must be r");
    }
  }

  /// The input tags tile the code's blocks, 0 … 199, 200 … 209 and 210 …, in order and without
  /// gaps.
  static void CheckInputLayout(const std::vector<Tag>& tags, std::vector<std::string>* d) {
    int next = 0;
    for (const Tag& t : tags) {
      if (t.table != "input") continue;
      if (next == kInputRegisterCount && t.address == kInMqttFirst) next = kInMqttFirst;
      if (t.address != next) d->push_back(t.tag + ": expected address " + std::to_string(next));
      next = t.address + t.registers;
    }
    if (next != kInputAddressSpan) {
      d->push_back("input tags end at " + std::to_string(next) + ", the code serves up to " +
                   std::to_string(kInputAddressSpan));
    }
  }

  void CheckInputValues(const std::vector<Tag>& tags, std::vector<std::string>* d) {
    std::array<std::uint16_t, kInputAddressSpan> r{};
    if (map_->ReadInput(0, kInputRegisterCount, r.data()) != ModbusException::kNone ||
        map_->ReadInput(kInMqttFirst, kInMqttCount, &r[kInMqttFirst]) != ModbusException::kNone ||
        map_->ReadInput(kInHistoryFirst, kInHistoryCount, &r[kInHistoryFirst]) !=
            ModbusException::kNone) {
      d->push_back("reading the input image failed");
      return;
    }
    const auto ref = ReferenceInputValues(adc_.counts, report_);
    for (const Tag& t : tags) {
      if (t.table != "input" || t.address < 0 || t.address + t.registers > kInputAddressSpan) {
        continue;
      }
      const auto it = ref.find(t.tag);
      if (it == ref.end()) {
        d->push_back(t.tag + ": a tag the reference does not know");
        continue;
      }
      if (t.type != it->second.type)
        d->push_back(t.tag + ": " + t.type + ", not " + it->second.type);
      const double got = Decode(t.type, &r[static_cast<std::size_t>(t.address)]) *
                         std::strtod(t.scale.c_str(), nullptr);
      if (!(std::fabs(got - it->second.value) <= it->second.tol)) {
        std::ostringstream m;
        m << t.tag << " at " << t.address << " as " << t.type << " ×" << t.scale << " reads " << got
          << ", the sample holds " << it->second.value;
        d->push_back(m.str());
      }
    }
  }

  void CheckHoldingCoverage(const std::vector<Tag>& tags, std::vector<std::string>* d) {
    std::set<int> covered;
    for (const Tag& t : tags) {
      if (t.table != "holding") continue;
      for (int i = 0; i < t.registers; ++i) covered.insert(t.address + i);
    }
    for (int a = 0; a < 100; ++a) {
      std::uint16_t v = 0;
      const bool readable =
          map_->ReadHolding(static_cast<std::uint16_t>(a), 1, &v) == ModbusException::kNone;
      if (readable != covered.contains(a)) {
        d->push_back("holding " + std::to_string(a) + (readable ? " is served" : " is refused") +
                     (covered.contains(a) ? " but listed" : " but not listed"));
      }
    }
  }

  ModbusException WriteValue(const Tag& t, double v) {
    std::uint16_t regs[2] = {0, 0};
    if (t.type == "float32") {
      PackFloat32(static_cast<float>(v), regs);
    } else {
      if (v < 0 || v > 65535) return ModbusException::kIllegalDataValue;  // not encodable
      regs[0] = static_cast<std::uint16_t>(v);
    }
    return map_->WriteHolding(static_cast<std::uint16_t>(t.address), regs,
                              static_cast<std::uint16_t>(t.registers));
  }
  double ReadValue(const Tag& t) {
    std::uint16_t regs[2] = {0, 0};
    if (map_->ReadHolding(static_cast<std::uint16_t>(t.address),
                          static_cast<std::uint16_t>(t.registers),
                          regs) != ModbusException::kNone) {
      return std::nan("");
    }
    return Decode(t.type, regs);
  }
  void Lock() { g_now_us += kUnlockDurationUs + 1; }
  void Unlock() {
    const std::uint16_t key = kUnlockKey;
    (void)map_->WriteHolding(kHoldUnlock, &key, 1);
  }

  void CheckHolding(const Tag& t, std::vector<std::string>* d) {
    const double lo = std::strtod(t.min.c_str(), nullptr);
    const double hi = std::strtod(t.max.c_str(), nullptr);
    const double step = t.type == "float32" ? std::max(1e-3, 1e-3 * std::fabs(hi)) : 1.0;
    const bool is_protected = t.access == "rw-protected";
    if (t.access != "rw" && !is_protected) d->push_back(t.tag + ": access '" + t.access + "'");
    Lock();
    const ModbusException locked = WriteValue(t, lo);
    if (is_protected != (locked == ModbusException::kIllegalDataValue)) {
      d->push_back(t.tag + (is_protected ? ": written while locked" : ": refused while locked"));
    }
    for (double v : {lo, hi}) {
      Unlock();
      if (WriteValue(t, v) != ModbusException::kNone) {
        d->push_back(t.tag + ": " + std::to_string(v) + " (in range) refused");
      } else if (t.tag != "command" && t.tag != "unlock" && t.tag != "health_command" &&
                 std::fabs(ReadValue(t) - v) > std::fabs(v) * 1e-6) {
        d->push_back(t.tag + ": " + std::to_string(v) + " written, " +
                     std::to_string(ReadValue(t)) + " read back");
      }
    }
    for (double v : {lo - step, hi + step}) {
      Unlock();
      if (WriteValue(t, v) != ModbusException::kIllegalDataValue) {
        d->push_back(t.tag + ": " + std::to_string(v) + " (out of range) not refused with 03");
      }
    }
    if (t.tag == "command" && ReadValue(t) != 0) d->push_back("command does not read 0");
    if (t.tag == "unlock" && ReadValue(t) != 1) d->push_back("unlock does not read 1 when open");
    // Leave the device as a later check expects it: sensor frame, slot 0, locked.
    Unlock();
    if (t.type == "float32") (void)WriteValue(t, 0.0);
    if (t.tag == "cal_slot") (void)WriteValue(t, 0.0);
    Lock();
  }
};

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += "\n  " + x;
  return s;
}

TEST(RegisterMapTable, MarkdownAndCsvListTheSameTags) {
  std::vector<std::string> errors;
  const auto md = ParseMarkdown(ReadText("docs/spec/modbus-map.md"), &errors);
  const auto csv = ParseCsv(ReadText("docs/spec/modbus-map.csv"), &errors);
  EXPECT_TRUE(errors.empty()) << Join(errors);
  // 47 + 75 + 7 + 44 + 48 input tags (map v3: health, MQTT, tare history, rainflow bins), 27 +
  // 38 holding tags (16 + 5 gravity + 6 mount; health)
  EXPECT_EQ(md.size(), 286u);
  const auto diffs = CompareTables(md, csv);
  EXPECT_TRUE(diffs.empty()) << Join(diffs);
}

TEST(RegisterMapTable, CodeServesWhatTheCsvSays) {
  std::vector<std::string> errors;
  const auto csv = ParseCsv(ReadText("docs/spec/modbus-map.csv"), &errors);
  ASSERT_TRUE(errors.empty()) << Join(errors);
  CodeCheck check;
  const auto diffs = check.Run(csv);
  EXPECT_TRUE(diffs.empty()) << Join(diffs);
}

/// The checks are worth something only if a deliberate change to one side fails them.
TEST(RegisterMapTable, DeliberateChangesToEitherTableAreCaught) {
  std::vector<std::string> errors;
  const std::string md_text = ReadText("docs/spec/modbus-map.md");
  const std::string csv_text = ReadText("docs/spec/modbus-map.csv");
  const auto md = ParseMarkdown(md_text, &errors);
  const auto csv = ParseCsv(csv_text, &errors);
  ASSERT_TRUE(errors.empty()) << Join(errors);

  auto replaced = [](std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
  };
  // The markdown changes: a scale, a unit, a type.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"| 0.001 |", "| 0.01 |"},
           {"| m m m |", "| mm mm mm |"},
           {"| 58–59 | uint32 |", "| 58–59 | int32 |"}}) {
    std::vector<std::string> e;
    const auto changed = ParseMarkdown(replaced(md_text, from, to), &e);
    EXPECT_FALSE(CompareTables(changed, csv).empty()) << "markdown change not caught: " << from;
  }
  // The CSV changes, each against the code: an address, a type, a scale, a range, an access, a
  // unit.
  const std::vector<std::pair<std::string, std::string>> csv_changes = {
      {"input,6,2,float32,Fx_n", "input,8,2,float32,Fx_n"},
      {"input,58,2,uint32,overload_events", "input,58,2,int32,overload_events"},
      {"Fz_mn,mN,0.001", "Fz_mn,mN,0.01"},
      {"filter_length,samples,1,rw,1,256", "filter_length,samples,1,rw,1,255"},
      {"cal_slot,,1,rw-protected", "cal_slot,,1,rw"},
      {"tool_dx_m,m,1,rw-protected,-10,10", "tool_dx_m,m,1,rw-protected,-10,20"},
      {"b2_mvv,mV/V", "b2_mvv,V"},
  };
  for (const auto& [from, to] : csv_changes) {
    std::vector<std::string> e;
    const auto changed = ParseCsv(replaced(csv_text, from, to), &e);
    CodeCheck check;
    const bool caught = !check.Run(changed).empty() || !CompareTables(md, changed).empty();
    EXPECT_TRUE(caught) << "csv change not caught: " << from << " → " << to;
    EXPECT_FALSE(CodeCheck().Run(changed).empty()) << "code check misses: " << from;
  }
}

}  // namespace
}  // namespace ftstack::fw
