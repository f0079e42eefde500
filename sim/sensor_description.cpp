#include "sim/sensor_description.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sim/default_sensor.hpp"
#include "sim/default_sensor_json.hpp"
#include "sim/json_positions.hpp"

namespace ftstack::sim {
namespace {

using nlohmann::json;

/// One description text being read: every error names origin:line:column and the JSON pointer.
class Reader {
 public:
  Reader(const std::string& text, std::string origin) : text_(text), origin_(std::move(origin)) {
    try {
      root_ = json::parse(text);
    } catch (const json::parse_error& e) {
      throw SensorDescriptionError(
          origin_ + ":" + LineColumnAt(text, e.byte == 0 ? 0 : e.byte - 1) + ": not valid JSON");
    } catch (const json::exception& e) {
      // Number overflow and the like: nlohmann names the token ("… parsing '1e999'"); find it.
      const std::string what = e.what();
      const std::size_t q = what.find("parsing '");
      std::size_t at = 0;
      if (q != std::string::npos) {
        const std::string token = what.substr(q + 9, what.find('\'', q + 9) - (q + 9));
        at = text.find(token);
        if (at == std::string::npos) at = 0;
      }
      throw SensorDescriptionError(origin_ + ":" + LineColumnAt(text, at) +
                                   ": number out of range");
    }
  }
  const json& root() const { return root_; }

  [[noreturn]] void Fail(const std::string& ptr, const std::string& msg) const {
    // Positions are needed only for an error: scanned then, not for every text read.
    if (!positions_) positions_ = std::make_unique<JsonPositions>(text_);
    throw SensorDescriptionError(origin_ + ":" + positions_->LineColumn(ptr) + ": " + msg +
                                 (ptr.empty() ? "" : " (at " + ptr + ")"));
  }

  const json& Object(const json& parent, const std::string& ptr, const std::string& key) const {
    if (!parent.contains(key)) Fail(ptr, "missing '" + key + "'");
    const json& v = parent.at(key);
    if (!v.is_object()) Fail(ptr + "/" + key, "'" + key + "' must be an object");
    return v;
  }

  void OnlyKeys(const json& obj, const std::string& ptr,
                std::initializer_list<const char*> allowed) const {
    const std::set<std::string> ok(allowed.begin(), allowed.end());
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      if (ok.count(it.key()) == 0) Fail(ptr + "/" + it.key(), "unknown key '" + it.key() + "'");
    }
  }

  double Num(const json& v, const std::string& ptr, const std::string& what) const {
    if (!v.is_number()) Fail(ptr, what + " is not a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) Fail(ptr, what + " is not finite");
    return d;
  }

  double Num(const json& obj, const std::string& ptr, const std::string& key,
             const double* fallback) const {
    if (!obj.contains(key)) {
      if (fallback == nullptr) Fail(ptr, "missing '" + key + "'");
      return *fallback;
    }
    return Num(obj.at(key), ptr + "/" + key, "'" + key + "'");
  }
  double Required(const json& obj, const std::string& ptr, const std::string& key) const {
    return Num(obj, ptr, key, nullptr);
  }
  double Optional(const json& obj, const std::string& ptr, const std::string& key,
                  double fallback) const {
    return Num(obj, ptr, key, &fallback);
  }
  double Positive(const json& obj, const std::string& ptr, const std::string& key) const {
    const double v = Required(obj, ptr, key);
    if (v <= 0) Fail(ptr + "/" + key, "'" + key + "' must be > 0");
    return v;
  }
  long Integer(const json& obj, const std::string& ptr, const std::string& key, long lo, long hi,
               const long* fallback) const {
    if (!obj.contains(key) && fallback != nullptr) return *fallback;
    const double v = Required(obj, ptr, key);
    if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
      Fail(ptr + "/" + key, "'" + key + "' must be an integer in " + std::to_string(lo) + " … " +
                                std::to_string(hi));
    }
    return static_cast<long>(v);
  }
  std::string String(const json& obj, const std::string& ptr, const std::string& key,
                     const std::string& fallback) const {
    if (!obj.contains(key)) return fallback;
    if (!obj.at(key).is_string()) Fail(ptr + "/" + key, "'" + key + "' must be a string");
    return obj.at(key).get<std::string>();
  }
  Wrench Rated(const json& obj, const std::string& ptr) const {
    Wrench r = DefaultRated();
    if (!obj.contains("rated")) return r;
    const json& a = obj.at("rated");
    if (!a.is_array() || a.size() != 6) Fail(ptr + "/rated", "'rated' needs 6 numbers");
    for (std::size_t k = 0; k < 6; ++k) {
      r(static_cast<int>(k)) = Num(a[k], ptr + "/rated/" + std::to_string(k), "rated");
      if (r(static_cast<int>(k)) <= 0)
        Fail(ptr + "/rated/" + std::to_string(k), "rated must be > 0");
    }
    return r;
  }

 private:
  const std::string& text_;  // outlives the reader (ParseSensorDescription's argument)
  std::string origin_;
  json root_;
  mutable std::unique_ptr<JsonPositions> positions_;
};

void CheckSchema(const Reader& rd) {
  const json& j = rd.root();
  if (!j.is_object() || !j.contains("schema") || j["schema"] != "ftstack-sensor/1") {
    rd.Fail(j.is_object() && j.contains("schema") ? "/schema" : "",
            "schema is not 'ftstack-sensor/1'");
  }
}

BeamFace Face(const Reader& rd, const json& g, const std::string& ptr) {
  const std::string f = rd.String(g, ptr, "face", "");
  if (f == "top") return BeamFace::kTop;
  if (f == "bottom") return BeamFace::kBottom;
  if (f == "plus_y") return BeamFace::kPlusY;
  if (f == "minus_y") return BeamFace::kMinusY;
  rd.Fail(ptr + "/face", "face must be top, bottom, plus_y or minus_y");
}

BridgeKind Kind(const Reader& rd, const std::string& s, const std::string& ptr) {
  if (s == "quarter") return BridgeKind::kQuarter;
  if (s == "half") return BridgeKind::kHalf;
  if (s == "full") return BridgeKind::kFull;
  rd.Fail(ptr, "bridge kind must be quarter, half or full");
}

BridgeWiring Wiring(const Reader& rd, const std::string& s, const std::string& ptr) {
  if (s == "two_wire") return BridgeWiring::kTwoWire;
  if (s == "three_wire") return BridgeWiring::kThreeWire;
  if (s == "four_wire") return BridgeWiring::kFourWire;
  if (s == "six_wire") return BridgeWiring::kSixWire;
  rd.Fail(ptr, "wiring must be two_wire, three_wire, four_wire or six_wire");
}

/// One gauge of a bridge arm: its beam, position along it, face, offset and angle.
GaugeSite ReadArm(const Reader& rd, const json& arm, const std::string& pa,
                  const FlexureGeometry& body) {
  GaugeSite site;
  site.beam = static_cast<int>(rd.Integer(arm, pa, "beam", 0, body.beam_count - 1, nullptr));
  site.position_m = rd.Required(arm, pa, "position_m");
  const double length = body.rim_radius_m - body.hub_radius_m;
  if (site.position_m < 0 || site.position_m > length) {
    rd.Fail(pa + "/position_m",
            "position_m must lie on the beam (0 … " + std::to_string(length) + " m)");
  }
  site.face = Face(rd, arm, pa);
  site.offset_m = rd.Optional(arm, pa, "offset_m", 0.0);
  const bool top_bottom = site.face == BeamFace::kTop || site.face == BeamFace::kBottom;
  const double half = 0.5 * (top_bottom ? body.beam_width_m : body.beam_height_m);
  if (std::abs(site.offset_m) > half) rd.Fail(pa + "/offset_m", "offset_m lies off the face");
  site.angle_deg = rd.Optional(arm, pa, "angle_deg", 0.0);
  return site;
}

/// The electrical defaults and the bridges with their arms (gauge sites).
void ReadBridges(const Reader& rd, const json& m, const std::string& p, FlexureSensorSpec* s) {
  BridgeCircuit defaults;
  const std::string pe = p + "/electrical";
  if (m.contains("electrical")) {
    const json& e = rd.Object(m, p, "electrical");
    rd.OnlyKeys(e, pe, {"excitation_v", "wiring", "lead_ohm"});
    defaults.excitation_v = rd.Positive(e, pe, "excitation_v");
    defaults.wiring = Wiring(rd, rd.String(e, pe, "wiring", "six_wire"), pe + "/wiring");
    defaults.lead_ohm = rd.Optional(e, pe, "lead_ohm", 0.0);
  }

  const std::string pbr = p + "/bridges";
  if (!m.contains("bridges") || !m["bridges"].is_array() || m["bridges"].empty() ||
      m["bridges"].size() > 8) {
    rd.Fail(m.contains("bridges") ? pbr : p, "'bridges' needs 1 … 8 bridges");
  }
  for (std::size_t b = 0; b < m["bridges"].size(); ++b) {
    const json& br = m["bridges"][b];
    const std::string pi = pbr + "/" + std::to_string(b);
    if (!br.is_object()) rd.Fail(pi, "a bridge must be an object");
    rd.OnlyKeys(br, pi, {"kind", "wiring", "lead_ohm", "completion_ohm", "arms"});
    BridgeSpec spec;
    spec.circuit = defaults;
    spec.circuit.kind = Kind(rd, rd.String(br, pi, "kind", "full"), pi + "/kind");
    if (br.contains("wiring"))
      spec.circuit.wiring = Wiring(rd, rd.String(br, pi, "wiring", ""), pi + "/wiring");
    spec.circuit.lead_ohm = rd.Optional(br, pi, "lead_ohm", defaults.lead_ohm);
    spec.circuit.completion_ohm = rd.Optional(br, pi, "completion_ohm", 0.0);
    try {
      BridgeCircuit check = spec.circuit;
      if (check.completion_ohm == 0) check.completion_ohm = s->gauge.resistance_ohm;
      ValidateBridge(check);
    } catch (const std::invalid_argument& e) {
      rd.Fail(pi, e.what());
    }
    const int active = spec.circuit.kind == BridgeKind::kQuarter ? 1
                       : spec.circuit.kind == BridgeKind::kHalf  ? 2
                                                                 : 4;
    if (!br.contains("arms") || !br["arms"].is_array() ||
        br["arms"].size() != static_cast<std::size_t>(active)) {
      rd.Fail(br.contains("arms") ? pi + "/arms" : pi,
              "'arms' needs " + std::to_string(active) + " gauge(s) (R1 … R" +
                  std::to_string(active) + ") for a " + rd.String(br, pi, "kind", "full") +
                  " bridge");
    }
    for (int a = 0; a < active; ++a) {
      const json& arm = br["arms"][static_cast<std::size_t>(a)];
      const std::string pa = pi + "/arms/" + std::to_string(a);
      if (!arm.is_object()) rd.Fail(pa, "an arm must be an object");
      rd.OnlyKeys(arm, pa, {"beam", "position_m", "face", "offset_m", "angle_deg"});
      const GaugeSite site = ReadArm(rd, arm, pa, s->body);
      spec.arm_gauge[static_cast<std::size_t>(a)] = static_cast<int>(s->gauges.size());
      s->gauges.push_back(site);
    }
    s->bridges.push_back(spec);
  }
}

FlexureSensorSpec ReadFlexure(const Reader& rd, const json& m, const std::string& p,
                              const std::string& name) {
  rd.OnlyKeys(m, p,
              {"type", "rated", "material", "body", "gauge", "electrical", "bridges",
               "max_condition_number"});
  FlexureSensorSpec s;
  s.name = name;
  s.rated = rd.Rated(m, p);
  s.max_condition_number = rd.Optional(m, p, "max_condition_number", 10.0);

  const std::string pm = p + "/material";
  const json& mat = rd.Object(m, p, "material");
  rd.OnlyKeys(mat, pm, {"name", "E_pa", "poisson", "modulus_tc_per_k", "allowable_strain"});
  s.body.e_pa = rd.Positive(mat, pm, "E_pa");
  s.body.poisson = rd.Optional(mat, pm, "poisson", 0.3);
  if (s.body.poisson <= -1 || s.body.poisson >= 0.5)
    rd.Fail(pm + "/poisson", "poisson must lie in (-1, 0.5)");
  s.modulus_tc_per_k = rd.Optional(mat, pm, "modulus_tc_per_k", 0.0);
  s.allowable_strain = rd.Optional(mat, pm, "allowable_strain", 0.0);

  const std::string pb = p + "/body";
  const json& body = rd.Object(m, p, "body");
  rd.OnlyKeys(body, pb,
              {"beams", "hub_radius_m", "rim_radius_m", "beam_width_m", "beam_height_m",
               "first_beam_deg", "rim_compliance"});
  s.body.beam_count = static_cast<int>(rd.Integer(body, pb, "beams", 3, 4, nullptr));
  s.body.hub_radius_m = rd.Required(body, pb, "hub_radius_m");
  s.body.rim_radius_m = rd.Required(body, pb, "rim_radius_m");
  if (s.body.hub_radius_m < 0 || s.body.rim_radius_m <= s.body.hub_radius_m) {
    rd.Fail(pb + "/rim_radius_m", "need 0 <= hub_radius_m < rim_radius_m");
  }
  s.body.beam_width_m = rd.Positive(body, pb, "beam_width_m");
  s.body.beam_height_m = rd.Positive(body, pb, "beam_height_m");
  s.body.first_beam_deg = rd.Optional(body, pb, "first_beam_deg", 0.0);
  if (body.contains("rim_compliance")) {
    const json& c = body["rim_compliance"];
    const std::string pc = pb + "/rim_compliance";
    if (!c.is_array() || c.size() != 6) {
      rd.Fail(pc, "rim_compliance needs 6 numbers (ux uy uz m/N, rx ry rz rad/(N·m))");
    }
    for (std::size_t k = 0; k < 6; ++k) {
      s.body.rim_compliance[k] = rd.Num(c[k], pc + "/" + std::to_string(k), "rim_compliance");
      if (s.body.rim_compliance[k] < 0)
        rd.Fail(pc + "/" + std::to_string(k), "compliance must be >= 0");
    }
  }

  const std::string pg = p + "/gauge";
  const json& g = rd.Object(m, p, "gauge");
  rd.OnlyKeys(g, pg,
              {"resistance_ohm", "gauge_factor", "transverse_sensitivity", "calibration_poisson",
               "thermal_output_per_k", "gauge_factor_tc_per_k", "self_heating_k_per_w"});
  s.gauge.resistance_ohm = rd.Optional(g, pg, "resistance_ohm", 120.0);
  s.gauge.gauge_factor = rd.Optional(g, pg, "gauge_factor", 2.0);
  s.gauge.transverse_sensitivity = rd.Optional(g, pg, "transverse_sensitivity", 0.0);
  s.gauge.calibration_poisson = rd.Optional(g, pg, "calibration_poisson", 0.285);
  s.gauge.thermal_output_per_k = rd.Optional(g, pg, "thermal_output_per_k", 0.0);
  s.gauge.gauge_factor_tc_per_k = rd.Optional(g, pg, "gauge_factor_tc_per_k", 0.0);
  s.gauge.self_heating_k_per_w = rd.Optional(g, pg, "self_heating_k_per_w", 0.0);
  if (s.gauge.resistance_ohm <= 0 || s.gauge.gauge_factor <= 0 ||
      std::abs(s.gauge.transverse_sensitivity) >= 0.5 || s.gauge.self_heating_k_per_w < 0) {
    rd.Fail(pg, "gauge: resistance and gauge factor must be > 0, |Kt| < 0.5, self heating >= 0");
  }

  ReadBridges(rd, m, p, &s);
  return s;
}

AdcSpec ReadAdc(const Reader& rd, const FlexureSensorSpec* flexure) {
  AdcSpec a;
  a.chip = AdcChip::kGeneric;
  a.generic.noise_rms_mvv = kDefaultNoiseMvv;
  a.excitation_v = flexure != nullptr ? flexure->bridges.front().circuit.excitation_v : 5.0;
  const json& j = rd.root();
  if (!j.contains("adc")) return a;
  const std::string p = "/adc";
  const json& adc = rd.Object(j, "", "adc");
  const std::string type = rd.String(adc, p, "type", "generic");
  const long g128 = 128;
  if (type == "generic") {
    rd.OnlyKeys(adc, p, {"type", "noise_mvv", "bits", "reference_ratio", "gain", "rate_hz"});
    a.generic.noise_rms_mvv = rd.Optional(adc, p, "noise_mvv", kDefaultNoiseMvv);
    if (a.generic.noise_rms_mvv < 0) rd.Fail(p + "/noise_mvv", "noise_mvv must be >= 0");
    const long b24 = 24;
    a.generic.resolution_bits = static_cast<int>(rd.Integer(adc, p, "bits", 8, 31, &b24));
    a.generic.reference_ratio = rd.Optional(adc, p, "reference_ratio", 0.5);
    if (a.generic.reference_ratio <= 0)
      rd.Fail(p + "/reference_ratio", "reference_ratio must be > 0");
  } else if (type == "hx711" || type == "ads131m0x") {
    rd.OnlyKeys(adc, p, {"type", "gain", "rate_hz", "excitation_v", "reference_v", "global_chop"});
    a.chip = type == "hx711" ? AdcChip::kHx711 : AdcChip::kAds131m0x;
    a.excitation_v = rd.Optional(adc, p, "excitation_v", a.excitation_v);
    a.reference_v = rd.Optional(adc, p, "reference_v", 1.2);
    if (adc.contains("global_chop")) {
      if (!adc["global_chop"].is_boolean())
        rd.Fail(p + "/global_chop", "global_chop must be true or false");
      a.global_chop = adc["global_chop"].get<bool>();
    }
  } else {
    rd.Fail(p + "/type", "adc type must be generic, hx711 or ads131m0x");
  }
  a.gain = static_cast<std::uint16_t>(rd.Integer(adc, p, "gain", 1, 128, &g128));
  const long r1000 = type == "hx711" ? 10 : 1000;
  a.rate_hz = static_cast<std::uint32_t>(rd.Integer(adc, p, "rate_hz", 1, 1000000, &r1000));
  try {
    (void)MakeAdcOperatingPoint(a);
  } catch (const std::invalid_argument& e) {
    rd.Fail(p, e.what());
  }
  return a;
}

std::shared_ptr<const SensorModel> ReadLinear(const Reader& rd, const json& m, const std::string& p,
                                              const std::string& name) {
  if (!m.contains("sensitivity_mvv")) rd.Fail(p, "missing 'sensitivity_mvv'");
  const json& s = m["sensitivity_mvv"];
  const std::string ps = p + "/sensitivity_mvv";
  if (!s.is_array() || s.empty() || s.size() > 8) rd.Fail(ps, "sensitivity_mvv needs 1..8 rows");
  const int n = static_cast<int>(s.size());
  Eigen::MatrixXd sens(n, 6);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::string pr = ps + "/" + std::to_string(i);
    if (!s[i].is_array() || s[i].size() != 6) rd.Fail(pr, "sensitivity row needs 6 numbers");
    for (std::size_t k = 0; k < 6; ++k) {
      sens(static_cast<int>(i), static_cast<int>(k)) =
          rd.Num(s[i][k], pr + "/" + std::to_string(k), "sensitivity");
    }
  }
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  if (m.contains("zero_mvv")) {
    const json& z = m["zero_mvv"];
    if (!z.is_array() || z.size() != s.size())
      rd.Fail(p + "/zero_mvv", "zero_mvv needs one number per row");
    for (std::size_t i = 0; i < z.size(); ++i) {
      zero(static_cast<int>(i)) = rd.Num(z[i], p + "/zero_mvv/" + std::to_string(i), "zero_mvv");
    }
  }
  return std::make_shared<LinearSensorModel>(sens, rd.Rated(m, p), name, zero);
}

std::unique_ptr<PhysicalSensorModel> BuildPhysical(const Reader& rd, FlexureSensorSpec spec) {
  try {
    return std::make_unique<PhysicalSensorModel>(std::move(spec));
  } catch (const std::invalid_argument& e) {
    rd.Fail("/model", e.what());
  }
}

}  // namespace

SensorDescription ParseSensorDescription(const std::string& text, const std::string& origin) {
  const Reader rd(text, origin);
  CheckSchema(rd);
  const json& j = rd.root();
  SensorDescription d;
  d.name = rd.String(j, "", "name", origin);
  const json& m = rd.Object(j, "", "model");
  const std::string type = rd.String(m, "/model", "type", "");
  FlexureSensorSpec flexure;
  if (type == "linear") {
    d.model = ReadLinear(rd, m, "/model", d.name);
  } else if (type == "flexure") {
    flexure = ReadFlexure(rd, m, "/model", d.name);
    d.model = BuildPhysical(rd, flexure);
  } else {
    rd.Fail(m.contains("type") ? "/model/type" : "/model",
            "unknown model type '" + type + "' (linear or flexure)");
  }
  d.adc_spec = ReadAdc(rd, type == "flexure" ? &flexure : nullptr);
  const AdcOperatingPoint op = MakeAdcOperatingPoint(d.adc_spec);
  d.adc = op.params;
  // The noise figure is the one at rate_hz, but recordings and ftd run the description's converter
  // at the rate they need: only AdcParamsAt() pins the rate (and its noise) in the HAL.
  d.adc.required_rate_hz = 0;
  d.adc_gain = d.adc_spec.gain;
  d.rate_hz = d.adc_spec.rate_hz;
  return d;
}

std::unique_ptr<PhysicalSensorModel> ParsePhysicalSensor(const std::string& text,
                                                         const std::string& origin) {
  const Reader rd(text, origin);
  CheckSchema(rd);
  const json& m = rd.Object(rd.root(), "", "model");
  if (rd.String(m, "/model", "type", "") != "flexure")
    rd.Fail("/model", "model type is not 'flexure'");
  return BuildPhysical(rd, ReadFlexure(rd, m, "/model", rd.String(rd.root(), "", "name", origin)));
}

const std::string& DefaultSensorJson() {
  static const std::string text = generated::kDefaultSensorJson;
  return text;
}

SensorDescription DefaultSensorDescription() {
  return ParseSensorDescription(DefaultSensorJson(), "builtin:sim/sensors/default.json");
}

SensorDescription LoadSensorDescription(const std::string& path) {
  if (path.empty() || path == "builtin") return DefaultSensorDescription();
  std::ifstream in(path);
  if (!in) throw SensorDescriptionError(path + ":1:1: cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseSensorDescription(ss.str(), path);
}

hal::sim::SimAdcParams AdcParamsAt(const SensorDescription& d, std::uint32_t rate_hz) {
  AdcSpec spec = d.adc_spec;
  spec.rate_hz = rate_hz;
  hal::sim::SimAdcParams p = MakeAdcOperatingPoint(spec).params;
  p.seed = d.adc.seed;
  p.realtime = d.adc.realtime;
  return p;
}

}  // namespace ftstack::sim
