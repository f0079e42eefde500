// Parsing and resolving --effect arguments against the effect vocabulary
// (measurement/effect_vocabulary.hpp): keys, value syntax, defaults and ranges.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

#include "measurement/wrench.hpp"
#include "sim/effects.hpp"

namespace ftstack::sim {
namespace {

const EffectDef& DefOf(const std::string& name, const std::string& text) {
  const EffectDef* def = FindEffect(name);
  if (def == nullptr) {
    throw EffectSpecError("--effect '" + text + "': unknown effect '" + name +
                          "' (known: " + EffectNameList() + ")");
  }
  return *def;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double ParseNumber(const std::string& v, const std::string& text, const std::string& key) {
  const char* begin = v.c_str();
  char* end = nullptr;
  const double d = v.empty() ? NAN : std::strtod(begin, &end);
  if (v.empty() || end != begin + v.size() || !std::isfinite(d)) {
    throw EffectSpecError("--effect '" + text + "': " + key + "='" + v +
                          "' is not a finite number");
  }
  return d;
}

std::vector<std::string> SplitList(std::string v) {
  if (v.size() >= 2 && v.front() == '[' && v.back() == ']') v = v.substr(1, v.size() - 2);
  std::vector<std::string> out;
  std::string cur;
  for (const char c : v) {
    if (c == ',' || c == '/') {
      out.push_back(cur);
      cur.clear();
    } else if (c != ' ') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

std::vector<double> ParseList(const std::string& v, const std::string& text,
                              const std::string& key) {
  std::vector<double> out;
  for (const auto& item : SplitList(v)) out.push_back(ParseNumber(item, text, key));
  return out;
}

// Checks a value's syntax for its type (ranges are checked when resolving).
void CheckValue(ParamType type, const std::string& v, const std::string& text,
                const std::string& key) {
  switch (type) {
    case ParamType::kNumber:
      (void)ParseNumber(v, text, key);
      break;
    case ParamType::kList:
      (void)ParseList(v, text, key);
      break;
    case ParamType::kChannels:
      if (Lower(v) == "all") break;
      for (const auto& item : SplitList(v)) {
        const double d = ParseNumber(item, text, key);
        if (d < 0 || d != std::floor(d)) {
          throw EffectSpecError("--effect '" + text + "': channel '" + item +
                                "' is not a bridge index (0, 1, …)");
        }
      }
      break;
    case ParamType::kRotAxis: {
      const std::string a = Lower(v);
      if (a != "x" && a != "y" && a != "z") {
        throw EffectSpecError("--effect '" + text + "': axis='" + v + "' must be x, y or z");
      }
      break;
    }
    case ParamType::kLoadAxis: {
      bool ok = false;
      for (const char* a : kWrenchAxisNames) ok = ok || Lower(v) == Lower(a);
      if (!ok) {
        throw EffectSpecError("--effect '" + text + "': axis='" + v +
                              "' must be one of Fx, Fy, Fz, Mx, My, Mz");
      }
      break;
    }
  }
}

const std::string* Find(const EffectSpec& s, const std::string& key) {
  for (const auto& [k, v] : s.params) {
    if (k == key) return &v;
  }
  return nullptr;
}

double NumOr(const EffectSpec& s, const std::string& key, double dflt) {
  const std::string* v = Find(s, key);
  return v ? ParseNumber(*v, s.text, key) : dflt;
}

[[noreturn]] void Range(const EffectSpec& s, const std::string& what) {
  throw EffectSpecError("--effect '" + s.text + "': " + what);
}

std::vector<int> ChannelsOr(const EffectSpec& s, int n, std::vector<int> dflt) {
  const std::string* v = Find(s, "channels");
  if (!v || Lower(*v) == "all") {
    if (v) dflt.clear();
    if (dflt.empty()) {
      for (int i = 0; i < n; ++i) dflt.push_back(i);
    }
    return dflt;
  }
  std::vector<int> out;
  for (const auto& item : SplitList(*v)) {
    const int c = static_cast<int>(ParseNumber(item, s.text, "channels"));
    if (c >= n)
      Range(s, "channel " + std::to_string(c) + " does not exist (the sensor has " +
                   std::to_string(n) + " bridges)");
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

double Sign(SeededRandom& rng) { return rng.Uniform() < 0.5 ? -1.0 : 1.0; }

// Per-channel values: given as one number (all channels) or one per listed channel; otherwise
// random magnitudes in [lo, hi) with random signs.
std::vector<double> PerChannel(const EffectSpec& s, const std::string& key,
                               const std::vector<int>& ch, int n, SeededRandom& rng, double lo,
                               double hi) {
  std::vector<double> out(static_cast<std::size_t>(n), 0.0);
  const std::string* v = Find(s, key);
  if (!v) {
    for (const int c : ch) out[static_cast<std::size_t>(c)] = Sign(rng) * rng.Uniform(lo, hi);
    return out;
  }
  const auto vals = ParseList(*v, s.text, key);
  if (vals.size() != 1 && vals.size() != ch.size()) {
    Range(s, key + " needs 1 value or one per channel (" + std::to_string(ch.size()) + ")");
  }
  for (std::size_t i = 0; i < ch.size(); ++i) {
    out[static_cast<std::size_t>(ch[i])] = vals.size() == 1 ? vals[0] : vals[i];
  }
  return out;
}

}  // namespace

const std::vector<std::string>& EffectNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& d : kEffectVocabulary) v.emplace_back(d.name);
    return v;
  }();
  return names;
}

std::vector<std::string> EffectKeys(const std::string& name) {
  std::vector<std::string> keys;
  for (const auto& p : DefOf(name, name).params) {
    if ((p.roles & kInjected) != 0) keys.emplace_back(p.key);
  }
  return keys;
}

EffectSpec ParseEffectSpec(const std::string& text) {
  EffectSpec s;
  s.text = text;
  const auto colon = text.find(':');
  s.name = text.substr(0, colon);
  const EffectDef& def = DefOf(s.name, text);
  if (colon == std::string::npos) return s;
  const std::string rest = text.substr(colon + 1);
  std::vector<std::string> items;
  std::string cur;
  int depth = 0;
  for (const char c : rest) {
    if (c == '[') ++depth;
    if (c == ']') --depth;
    if (c == ',' && depth == 0) {
      items.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  items.push_back(cur);
  if (depth != 0) throw EffectSpecError("--effect '" + text + "': unbalanced [ ]");
  for (const auto& item : items) {
    if (item.empty() && items.size() == 1) break;  // "name:" with nothing after
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw EffectSpecError("--effect '" + text + "': '" + item + "' is not key=value");
    }
    // Keys are checked against the vocabulary; an alias is stored under its canonical key.
    const EffectParam* kd = FindParam(def, item.substr(0, eq));
    if (kd == nullptr || (kd->roles & kInjected) == 0) {
      throw EffectSpecError("--effect '" + text + "': unknown key '" + item.substr(0, eq) +
                            "' for " + s.name + " (keys: " + ValidKeys(def, kInjected) + ")");
    }
    const std::string key(kd->key);
    const std::string value = item.substr(eq + 1);
    if (Find(s, key))
      throw EffectSpecError("--effect '" + text + "': key '" + key + "' given twice");
    CheckValue(kd->type, value, text, key);
    s.params.emplace_back(key, value);
  }
  return s;
}

std::string EffectAxisName(const Effect& e) {
  if (e.kind == EffectKind::kMisalignment && e.axis >= 0) return std::string(1, "xyz"[e.axis]);
  if (e.kind == EffectKind::kOverloadShift && e.axis >= 0)
    return kWrenchAxisNames[static_cast<std::size_t>(e.axis)];
  return "";
}

namespace {

double Positive(const EffectSpec& s, const std::string& key, double v) {
  if (!(v > 0.0)) Range(s, key + " must be > 0");
  return v;
}

// The effects on the output signal and on the load part (vocabulary order up to hysteresis).
void ResolveOutputSide(const EffectSpec& s, const EffectContext& ctx, SeededRandom& rng,
                       Effect& e) {
  const int n = ctx.channels;
  auto positive = [&](const std::string& key, double v) { return Positive(s, key, v); };
  switch (e.kind) {
    case EffectKind::kNone:
      break;
    case EffectKind::kZeroOffset:
      e.channels = ChannelsOr(s, n, {});
      e.per_channel_key = "offset";
      e.per_channel = PerChannel(s, "offset", e.channels, n, rng, 3e-4, 6e-4);
      break;
    case EffectKind::kZeroDrift:
      e.channels = ChannelsOr(s, n, {});
      e.num["amplitude_mvv"] = NumOr(s, "amplitude_mvv", 4e-4);
      if (e.num["amplitude_mvv"] < 0) Range(s, "amplitude_mvv must be >= 0");
      e.num["corner_hz"] = positive("corner_hz", NumOr(s, "corner_hz", 0.02));
      break;
    case EffectKind::kThermalZeroDrift:
      e.channels = ChannelsOr(s, n, {});
      e.per_channel_key = "coef_per_K";
      e.per_channel = PerChannel(s, "coef_per_K", e.channels, n, rng, 3e-5, 8e-5);
      e.num["t0_c"] = NumOr(s, "t0_c", ctx.t0_c);
      break;
    case EffectKind::kThermalSpanDrift:
      e.channels = ChannelsOr(s, n, {});
      e.num["coef_per_K"] = NumOr(s, "coef_per_K", -1.5e-4);
      e.num["t0_c"] = NumOr(s, "t0_c", ctx.t0_c);
      break;
    case EffectKind::kExcitationDrift:
      e.num["amplitude"] = NumOr(s, "amplitude", 1.5e-3);
      if (e.num["amplitude"] < 0 || e.num["amplitude"] > 0.5)
        Range(s, "amplitude must be in [0, 0.5]");
      e.num["corner_hz"] = positive("corner_hz", NumOr(s, "corner_hz", 0.02));
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    case EffectKind::kCreep:
      e.channels = ChannelsOr(s, n, {});
      e.num["tau_s"] = positive("tau_s", NumOr(s, "tau_s", 10.0));
      e.num["fraction"] = NumOr(s, "fraction", 4e-3);
      if (std::abs(e.num["fraction"]) > 0.5) Range(s, "fraction must be in [-0.5, 0.5]");
      break;
    case EffectKind::kHysteresis:
      e.num["amplitude"] = NumOr(s, "amplitude", 1.5e-3);
      if (std::abs(e.num["amplitude"]) > 0.2) Range(s, "amplitude must be in [-0.2, 0.2]");
      e.num["width"] = positive("width", NumOr(s, "width", 0.5));
      if (e.num["width"] > 2.0) Range(s, "width must be in (0, 2]");
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    default:
      break;
  }
}

// The effects on the bridges' shape, the load path, timing and read-out (vocabulary order from
// bridge_nonlinearity on).
void ResolveLoadSide(const EffectSpec& s, const EffectContext& ctx, SeededRandom& rng, Effect& e) {
  const int n = ctx.channels;
  auto positive = [&](const std::string& key, double v) { return Positive(s, key, v); };
  switch (e.kind) {
    case EffectKind::kBridgeNonlinearity:
      e.channels = ChannelsOr(s, n, {rng.Index(n)});
      e.num["coef"] = NumOr(s, "coef", -2e-3);
      break;
    case EffectKind::kGeometricNonlinearity:
      e.num["coef"] = NumOr(s, "coef", -3e-3);
      if (std::abs(e.num["coef"]) > 0.3) Range(s, "coef must be in [-0.3, 0.3]");
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    case EffectKind::kLoadStiffening:
      e.num["coef"] = NumOr(s, "coef", -8e-3);
      if (std::abs(e.num["coef"]) > 0.5) Range(s, "coef must be in [-0.5, 0.5]");
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    case EffectKind::kMisalignment: {
      const std::string* a = Find(s, "axis");
      e.axis = a ? Lower(*a)[0] - 'x' : 2;
      e.num["angle_deg"] = NumOr(s, "angle_deg", 0.15);
      if (std::abs(e.num["angle_deg"]) > 45.0) Range(s, "angle_deg must be in [-45, 45]");
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    }
    case EffectKind::kGainError: {
      const int ch = rng.Index(n);
      const double sign = Sign(rng);
      e.channels = ChannelsOr(s, n, {ch});
      e.num["gain"] = positive("gain", NumOr(s, "gain", 1.0 + sign * 2.5e-3));
      break;
    }
    case EffectKind::kTimeSkew:
      e.num["delay_s"] = NumOr(s, "delay_s", 0.005);
      if (std::abs(e.num["delay_s"]) > 0.1 * std::max(ctx.duration_s, 1e-9)) {
        Range(s, "|delay_s| must be below a tenth of the recording");
      }
      for (int i = 0; i < n; ++i) e.channels.push_back(i);
      break;
    case EffectKind::kSaturation:
      e.channels = ChannelsOr(s, n, {});
      e.num["limit"] = Find(s, "limit") ? positive("limit", NumOr(s, "limit", 1.0)) : NAN;
      break;
    case EffectKind::kOverloadShift: {
      const std::string* a = Find(s, "axis");
      e.axis = 2;
      for (int k = 0; a && k < 6; ++k) {
        if (Lower(*a) == Lower(kWrenchAxisNames[static_cast<std::size_t>(k)])) e.axis = k;
      }
      // Default: 55 % into the record (to 0.1 s), kept where the overload fits.
      const double dflt = std::round(0.55 * ctx.duration_s * 10.0) / 10.0;
      e.num["onset_s"] =
          NumOr(s, "onset_s", std::clamp(dflt, 0.7, std::max(0.7, ctx.duration_s - 1.4)));
      if (e.num["onset_s"] < 0.7 || e.num["onset_s"] > ctx.duration_s - 1.4) {
        Range(s, "onset_s must leave 0.7 s before and 1.4 s after it inside the recording");
      }
      e.num["shift"] = NumOr(s, "shift", Sign(rng) * 6e-4);
      e.num["factor"] = NumOr(s, "factor", 1.6);
      if (!(e.num["factor"] > 1.0)) Range(s, "factor (overload / rated) must be > 1");
      // The shift pattern follows the overloaded axis's sensitivity column (largest entry = shift).
      Eigen::VectorXd col = ctx.sensitivity.col(e.axis);
      const double m = col.cwiseAbs().maxCoeff();
      e.per_channel_key = "shift_mvv";
      e.per_channel.assign(static_cast<std::size_t>(n), 0.0);
      for (int i = 0; i < n; ++i) {
        e.per_channel[static_cast<std::size_t>(i)] = m > 0 ? e.num["shift"] * col(i) / m : 0.0;
        if (std::abs(col(i)) > 0.05 * m) e.channels.push_back(i);
      }
      break;
    }
    case EffectKind::kMainsInterference:
      e.channels = ChannelsOr(s, n, {});
      e.num["freq_hz"] = positive("freq_hz", NumOr(s, "freq_hz", 50.0));
      e.num["amplitude_mvv"] = NumOr(s, "amplitude_mvv", 2.5e-4);
      e.num["phase_deg"] = NumOr(s, "phase_deg", 0.0);
      break;
    case EffectKind::kConverterGlitch: {
      e.channels = ChannelsOr(s, n, {});
      const double count = NumOr(s, "count", 5.0);
      if (!(count >= 1.0) || count > 1e6 || count != std::floor(count)) {
        Range(s, "count must be a whole number of wrong codes, 1 … 1e6");
      }
      e.num["count"] = count;
      // Default: about 10^5 codes of a 24-bit converter at gain 128 (an HX711 bit error).
      e.num["offset_mvv"] = NumOr(s, "offset_mvv", 0.05);
      if (!(std::fabs(e.num["offset_mvv"]) > 0.0)) Range(s, "offset_mvv must be non-zero");
      break;
    }
    case EffectKind::kResonance:
      e.channels = ChannelsOr(s, n, {});
      e.num["freq_hz"] = positive("freq_hz", NumOr(s, "freq_hz", 25.0));
      e.num["damping_ratio"] = positive("damping_ratio", NumOr(s, "damping_ratio", 0.04));
      if (e.num["damping_ratio"] >= 1.0) Range(s, "damping_ratio must be in (0, 1) (ringing)");
      e.num["participation"] = NumOr(s, "participation", 0.01);
      if (!(e.num["participation"] > 0.0) || e.num["participation"] > 1.0) {
        Range(s, "participation must be in (0, 1]");
      }
      break;
    default:
      break;
  }
}

}  // namespace

Effect ResolveEffect(const EffectSpec& s, const EffectContext& ctx, int index) {
  const EffectDef& def = DefOf(s.name, s.text);
  Effect e;
  e.kind = def.kind;
  e.name = def.name;
  e.seed = ctx.seed * 1000003ULL + static_cast<std::uint64_t>(index) * 7919ULL +
           static_cast<std::uint64_t>(def.kind) * 104729ULL;
  SeededRandom rng(e.seed);
  if (def.kind < EffectKind::kBridgeNonlinearity) {
    ResolveOutputSide(s, ctx, rng, e);
  } else {
    ResolveLoadSide(s, ctx, rng, e);
  }
  return e;
}

}  // namespace ftstack::sim
