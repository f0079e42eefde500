#include "sim/effects.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

namespace ftstack::sim {
namespace {

enum class ValueType { kNumber, kList, kChannels, kRotAxis, kLoadAxis };

struct KeyDef {
  const char* key;
  ValueType type;
};

struct EffectDef {
  const char* name;
  EffectKind kind;
  std::vector<KeyDef> keys;
};

const std::vector<EffectDef>& Defs() {
  using V = ValueType;
  static const std::vector<EffectDef> defs = {
      {"none", EffectKind::kNone, {}},
      {"zero_offset", EffectKind::kZeroOffset, {{"offset", V::kList}, {"channels", V::kChannels}}},
      {"zero_drift",
       EffectKind::kZeroDrift,
       {{"amplitude", V::kNumber}, {"corner_hz", V::kNumber}, {"channels", V::kChannels}}},
      {"thermal_zero_drift",
       EffectKind::kThermalZeroDrift,
       {{"coef_per_K", V::kList}, {"t0_c", V::kNumber}, {"channels", V::kChannels}}},
      {"thermal_span_drift",
       EffectKind::kThermalSpanDrift,
       {{"coef_per_K", V::kNumber}, {"t0_c", V::kNumber}, {"channels", V::kChannels}}},
      {"excitation_drift",
       EffectKind::kExcitationDrift,
       {{"amplitude", V::kNumber}, {"corner_hz", V::kNumber}}},
      {"creep",
       EffectKind::kCreep,
       {{"tau_s", V::kNumber}, {"fraction", V::kNumber}, {"channels", V::kChannels}}},
      {"hysteresis", EffectKind::kHysteresis, {{"amplitude", V::kNumber}, {"width", V::kNumber}}},
      {"bridge_nonlinearity",
       EffectKind::kBridgeNonlinearity,
       {{"channels", V::kChannels}, {"coef", V::kNumber}}},
      {"geometric_nonlinearity", EffectKind::kGeometricNonlinearity, {{"coef", V::kNumber}}},
      {"load_stiffening", EffectKind::kLoadStiffening, {{"coef", V::kNumber}}},
      {"misalignment",
       EffectKind::kMisalignment,
       {{"axis", V::kRotAxis}, {"angle_deg", V::kNumber}}},
      {"gain_error", EffectKind::kGainError, {{"channels", V::kChannels}, {"gain", V::kNumber}}},
      {"time_skew", EffectKind::kTimeSkew, {{"delay_s", V::kNumber}}},
      {"saturation", EffectKind::kSaturation, {{"limit", V::kNumber}, {"channels", V::kChannels}}},
      {"overload_shift",
       EffectKind::kOverloadShift,
       {{"onset_s", V::kNumber},
        {"shift", V::kNumber},
        {"axis", V::kLoadAxis},
        {"factor", V::kNumber}}},
      {"mains_interference",
       EffectKind::kMainsInterference,
       {{"freq_hz", V::kNumber},
        {"amplitude", V::kNumber},
        {"phase_deg", V::kNumber},
        {"channels", V::kChannels}}},
      {"resonance",
       EffectKind::kResonance,
       {{"freq_hz", V::kNumber},
        {"damping_ratio", V::kNumber},
        {"participation", V::kNumber},
        {"channels", V::kChannels}}},
  };
  return defs;
}

const EffectDef& DefOf(const std::string& name, const std::string& text) {
  for (const auto& d : Defs()) {
    if (name == d.name) return d;
  }
  std::string list;
  for (const auto& d : Defs()) list += std::string(list.empty() ? "" : ", ") + d.name;
  throw EffectSpecError("--effect '" + text + "': unknown effect '" + name + "' (known: " + list +
                        ")");
}

const char* const kLoadAxes[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};

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
void CheckValue(ValueType type, const std::string& v, const std::string& text,
                const std::string& key) {
  switch (type) {
    case ValueType::kNumber:
      (void)ParseNumber(v, text, key);
      break;
    case ValueType::kList:
      (void)ParseList(v, text, key);
      break;
    case ValueType::kChannels:
      if (Lower(v) == "all") break;
      for (const auto& item : SplitList(v)) {
        const double d = ParseNumber(item, text, key);
        if (d < 0 || d != std::floor(d)) {
          throw EffectSpecError("--effect '" + text + "': channel '" + item +
                                "' is not a bridge index (0, 1, …)");
        }
      }
      break;
    case ValueType::kRotAxis: {
      const std::string a = Lower(v);
      if (a != "x" && a != "y" && a != "z") {
        throw EffectSpecError("--effect '" + text + "': axis='" + v + "' must be x, y or z");
      }
      break;
    }
    case ValueType::kLoadAxis: {
      bool ok = false;
      for (const char* a : kLoadAxes) ok = ok || Lower(v) == Lower(a);
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

Eigen::Matrix3d Rotation(int axis, double angle_deg) {
  const Eigen::Vector3d ax = Eigen::Vector3d::Unit(axis);
  return Eigen::AngleAxisd(angle_deg * std::numbers::pi / 180.0, ax).toRotationMatrix();
}

// First-order-hold response of a SISO system to u (per sample), starting at steady state.
std::vector<double> Filter(const FohSystem& sys, const Eigen::RowVectorXd& c, Eigen::VectorXd x,
                           const std::vector<double>& u) {
  std::vector<double> y(u.size());
  if (u.empty()) return y;
  y[0] = c * x;
  for (std::size_t k = 0; k + 1 < u.size(); ++k) {
    x = sys.phi * x + sys.gamma1 * u[k] + sys.gamma2 * (u[k + 1] - u[k]);
    y[k + 1] = c * x;
  }
  return y;
}

}  // namespace

const std::vector<std::string>& EffectNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& d : Defs()) v.emplace_back(d.name);
    return v;
  }();
  return names;
}

const std::vector<std::string>& EffectKeys(const std::string& name) {
  static std::map<std::string, std::vector<std::string>> cache = [] {
    std::map<std::string, std::vector<std::string>> m;
    for (const auto& d : Defs()) {
      auto& keys = m[d.name];
      for (const auto& k : d.keys) keys.emplace_back(k.key);
    }
    return m;
  }();
  (void)DefOf(name, name);
  return cache.at(name);
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
    const std::string key = item.substr(0, eq);
    const std::string value = item.substr(eq + 1);
    const KeyDef* kd = nullptr;
    for (const auto& k : def.keys) {
      if (key == k.key) kd = &k;
    }
    if (kd == nullptr) {
      std::string list;
      for (const auto& k : def.keys) list += std::string(list.empty() ? "" : ", ") + k.key;
      throw EffectSpecError("--effect '" + text + "': unknown key '" + key + "' for " + s.name +
                            " (keys: " + (list.empty() ? "none" : list) + ")");
    }
    if (Find(s, key))
      throw EffectSpecError("--effect '" + text + "': key '" + key + "' given twice");
    CheckValue(kd->type, value, text, key);
    s.params.emplace_back(key, value);
  }
  return s;
}

std::string EffectAxisName(const Effect& e) {
  if (e.kind == EffectKind::kMisalignment && e.axis >= 0) return std::string(1, "xyz"[e.axis]);
  if (e.kind == EffectKind::kOverloadShift && e.axis >= 0) return kLoadAxes[e.axis];
  return "";
}

Effect ResolveEffect(const EffectSpec& s, const EffectContext& ctx, int index) {
  const EffectDef& def = DefOf(s.name, s.text);
  Effect e;
  e.kind = def.kind;
  e.name = def.name;
  e.seed = ctx.seed * 1000003ULL + static_cast<std::uint64_t>(index) * 7919ULL +
           static_cast<std::uint64_t>(def.kind) * 104729ULL;
  SeededRandom rng(e.seed);
  const int n = ctx.channels;
  auto positive = [&](const std::string& key, double v) {
    if (!(v > 0.0)) Range(s, key + " must be > 0");
    return v;
  };
  switch (def.kind) {
    case EffectKind::kNone:
      break;
    case EffectKind::kZeroOffset:
      e.channels = ChannelsOr(s, n, {});
      e.per_channel_key = "offset";
      e.per_channel = PerChannel(s, "offset", e.channels, n, rng, 3e-4, 6e-4);
      break;
    case EffectKind::kZeroDrift:
      e.channels = ChannelsOr(s, n, {});
      e.num["amplitude"] = NumOr(s, "amplitude", 4e-4);
      if (e.num["amplitude"] < 0) Range(s, "amplitude must be >= 0");
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
        if (Lower(*a) == Lower(kLoadAxes[k])) e.axis = k;
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
      e.num["amplitude"] = NumOr(s, "amplitude", 2.5e-4);
      e.num["phase_deg"] = NumOr(s, "phase_deg", 0.0);
      break;
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
  }
  return e;
}

std::vector<double> Wander(const std::vector<double>& t_s, double amplitude, double corner_hz,
                           std::uint64_t seed) {
  std::vector<double> d(t_s.size(), 0.0);
  if (t_s.size() < 2 || amplitude == 0.0) return d;
  SeededRandom rng(seed ^ 0xD1B54A32D192ED03ULL);
  const double span = t_s.back() - t_s.front();
  const double f_lo = std::min(0.25 / span, 0.5 * corner_hz);
  constexpr int kTerms = 12;
  for (int k = 0; k < kTerms; ++k) {
    const double f = f_lo * std::pow(corner_hz / f_lo, static_cast<double>(k) / (kTerms - 1));
    const double a = std::abs(rng.Normal()) / f;
    const double ph = rng.Uniform(0.0, 2.0 * std::numbers::pi);
    for (std::size_t i = 0; i < t_s.size(); ++i) {
      d[i] += a * (std::sin(2.0 * std::numbers::pi * f * (t_s[i] - t_s[0]) + ph) - std::sin(ph));
    }
  }
  double ss = 0.0;
  for (const double v : d) ss += v * v;
  const double rms = std::sqrt(ss / static_cast<double>(d.size()));
  if (rms > 0) {
    for (double& v : d) v *= amplitude / rms;
  }
  return d;
}

FohSystem DiscretiseFoh(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double h_s) {
  const Eigen::Index n = a.rows();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 2, n + 2);
  m.topLeftCorner(n, n) = a * h_s;
  m.block(0, n, n, 1) = b * h_s;
  m(n, n + 1) = 1.0;
  const Eigen::MatrixXd e = m.exp();
  return {e.topLeftCorner(n, n), e.block(0, n, n, 1), e.block(0, n + 1, n, 1)};
}

Eigen::MatrixXd Compose(const std::vector<Effect>& effects, const ComposeInput& in) {
  const SensorModel& model = *in.model;
  const int n = model.channel_count();
  const std::size_t ns = in.t_s.size();
  const Wrench& r = in.rated;
  double delay = 0.0;
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kTimeSkew) delay += e.num.at("delay_s");
  }

  // 1. The load the sensor actually sees.
  constexpr int kPlays = 8;
  std::vector<std::array<double, 6 * kPlays>> play(effects.size());
  std::vector<std::array<double, 6 * kPlays>> thresholds(effects.size());
  std::vector<Eigen::Matrix3d> rot_t(effects.size(), Eigen::Matrix3d::Identity());
  for (std::size_t ei = 0; ei < effects.size(); ++ei) {
    const Effect& e = effects[ei];
    if (e.kind == EffectKind::kHysteresis) {
      for (int k = 0; k < 6; ++k) {
        for (int j = 0; j < kPlays; ++j) {
          thresholds[ei][static_cast<std::size_t>(k * kPlays + j)] =
              e.num.at("width") * r(k) * (j + 1) / kPlays;
        }
      }
    } else if (e.kind == EffectKind::kMisalignment) {
      rot_t[ei] = Rotation(e.axis, e.num.at("angle_deg")).transpose();
    }
  }
  std::vector<Wrench> seen(ns);
  for (std::size_t i = 0; i < ns; ++i) {
    Wrench w = in.profile->LoadAt(in.t_s[i] - delay);
    for (std::size_t ei = 0; ei < effects.size(); ++ei) {
      const Effect& e = effects[ei];
      switch (e.kind) {
        case EffectKind::kMisalignment: {
          // Sensor frame rotated by angle about the axis: it sees the load's components Rᵀ·F, Rᵀ·M.
          const Eigen::Matrix3d& rt = rot_t[ei];
          const Eigen::Vector3d f = rt * w.head<3>();
          const Eigen::Vector3d m = rt * w.tail<3>();
          w.head<3>() = f;
          w.tail<3>() = m;
          break;
        }
        case EffectKind::kLoadStiffening: {
          const double g = e.num.at("coef") * w(2) / r(2);
          for (const int k : {0, 1, 3, 4}) w(k) *= 1.0 + g;
          break;
        }
        case EffectKind::kGeometricNonlinearity:
          for (int k = 0; k < 6; ++k)
            w(k) += e.num.at("coef") * w(k) * (w(k) / r(k)) * (w(k) / r(k));
          break;
        case EffectKind::kHysteresis: {
          // Prandtl–Ishlinskii: the mean of kPlays play operators with thresholds
          // width·rated·j/kPlays, each normalised to ±1, scaled to amplitude·rated.
          auto& p = play[ei];
          Wrench d = Wrench::Zero();
          for (int k = 0; k < 6; ++k) {
            for (int j = 0; j < kPlays; ++j) {
              const double thr = thresholds[ei][static_cast<std::size_t>(k * kPlays + j)];
              double& pj = p[static_cast<std::size_t>(k * kPlays + j)];
              pj = i == 0 ? w(k) : std::clamp(pj, w(k) - thr, w(k) + thr);
              d(k) += (pj - w(k)) / thr;
            }
            d(k) *= e.num.at("amplitude") * r(k) / kPlays;
          }
          w += d;
          break;
        }
        default:
          break;
      }
    }
    seen[i] = w;
  }

  // 2. The model, split into its zero (temperature only) and the load part.
  Eigen::MatrixXd out(n, static_cast<Eigen::Index>(ns));
  Eigen::MatrixXd zero(n, static_cast<Eigen::Index>(ns));
  double last_t = NAN;
  Eigen::VectorXd z;
  for (std::size_t i = 0; i < ns; ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    out.col(c) = model.BridgeOutputs(seen[i], in.temp_c[i]);
    if (!(in.temp_c[i] == last_t)) {
      z = model.BridgeOutputs(Wrench::Zero(), in.temp_c[i]);
      last_t = in.temp_c[i];
    }
    zero.col(c) = z;
  }
  Eigen::MatrixXd load = out - zero;
  const double h = ns > 1 ? in.t_s[1] - in.t_s[0] : 1.0;

  // 3. Dynamics and sensitivity changes on the load part.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kCreep) {
      const double tau = e.num.at("tau_s");
      const FohSystem sys = DiscretiseFoh(Eigen::MatrixXd::Constant(1, 1, -1.0 / tau),
                                          Eigen::VectorXd::Constant(1, 1.0 / tau), h);
      for (const int ch : e.channels) {
        std::vector<double> u(ns);
        for (std::size_t i = 0; i < ns; ++i) u[i] = load(ch, static_cast<Eigen::Index>(i));
        const auto x =
            Filter(sys, Eigen::RowVectorXd::Ones(1), Eigen::VectorXd::Constant(1, u[0]), u);
        for (std::size_t i = 0; i < ns; ++i)
          load(ch, static_cast<Eigen::Index>(i)) += e.num.at("fraction") * x[i];
      }
    }
  }
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kResonance) {
      const double wn = 2.0 * std::numbers::pi * e.num.at("freq_hz");
      const double zeta = e.num.at("damping_ratio");
      Eigen::MatrixXd a(2, 2);
      a << 0.0, 1.0, -wn * wn, -2.0 * zeta * wn;
      const FohSystem sys = DiscretiseFoh(a, Eigen::Vector2d(0.0, wn * wn), h);
      Eigen::RowVectorXd c(2);
      c << 1.0, 0.0;
      for (const int ch : e.channels) {
        std::vector<double> u(ns);
        for (std::size_t i = 0; i < ns; ++i) u[i] = load(ch, static_cast<Eigen::Index>(i));
        const auto y = Filter(sys, c, Eigen::Vector2d(u[0], 0.0), u);
        // Only the mode's share of the output rings: L + p·(y − L).
        const double p = e.num.at("participation");
        for (std::size_t i = 0; i < ns; ++i) {
          load(ch, static_cast<Eigen::Index>(i)) = u[i] + p * (y[i] - u[i]);
        }
      }
    }
  }
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kThermalSpanDrift) {
      for (const int ch : e.channels) {
        for (std::size_t i = 0; i < ns; ++i) {
          load(ch, static_cast<Eigen::Index>(i)) *=
              1.0 + e.num.at("coef_per_K") * (in.temp_c[i] - e.num.at("t0_c"));
        }
      }
    } else if (e.kind == EffectKind::kGainError) {
      for (const int ch : e.channels) load.row(ch) *= e.num.at("gain");
    }
  }
  out = zero + load;

  // 4. Bridge and read-out effects on the whole output.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kBridgeNonlinearity) {
      for (const int ch : e.channels) {
        out.row(ch) += e.num.at("coef") * out.row(ch).cwiseAbs2();
      }
    } else if (e.kind == EffectKind::kExcitationDrift) {
      const auto d = Wander(in.t_s, e.num.at("amplitude"), e.num.at("corner_hz"), e.seed);
      for (std::size_t i = 0; i < ns; ++i) out.col(static_cast<Eigen::Index>(i)) *= 1.0 + d[i];
    }
  }

  // 5. Additive signals.
  for (const auto& e : effects) {
    switch (e.kind) {
      case EffectKind::kZeroOffset:
        for (const int ch : e.channels)
          out.row(ch).array() += e.per_channel[static_cast<std::size_t>(ch)];
        break;
      case EffectKind::kZeroDrift: {
        for (const int ch : e.channels) {
          const auto d = Wander(in.t_s, e.num.at("amplitude"), e.num.at("corner_hz"),
                                e.seed + static_cast<std::uint64_t>(ch) * 0x9E3779B9ULL);
          for (std::size_t i = 0; i < ns; ++i) out(ch, static_cast<Eigen::Index>(i)) += d[i];
        }
        break;
      }
      case EffectKind::kThermalZeroDrift:
        for (const int ch : e.channels) {
          for (std::size_t i = 0; i < ns; ++i) {
            out(ch, static_cast<Eigen::Index>(i)) +=
                e.per_channel[static_cast<std::size_t>(ch)] * (in.temp_c[i] - e.num.at("t0_c"));
          }
        }
        break;
      case EffectKind::kOverloadShift:
        for (std::size_t i = 0; i < ns; ++i) {
          if (in.t_s[i] >= e.num.at("onset_s")) {
            for (int ch = 0; ch < n; ++ch)
              out(ch, static_cast<Eigen::Index>(i)) += e.per_channel[static_cast<std::size_t>(ch)];
          }
        }
        break;
      case EffectKind::kMainsInterference: {
        const double w = 2.0 * std::numbers::pi * e.num.at("freq_hz");
        const double ph = e.num.at("phase_deg") * std::numbers::pi / 180.0;
        for (std::size_t i = 0; i < ns; ++i) {
          const double v = e.num.at("amplitude") * std::sin(w * in.t_s[i] + ph);
          for (const int ch : e.channels) out(ch, static_cast<Eigen::Index>(i)) += v;
        }
        break;
      }
      default:
        break;
    }
  }

  // 6. Clipping of the amplifier.
  for (const auto& e : effects) {
    if (e.kind == EffectKind::kSaturation) {
      const double lim = e.num.at("limit");
      for (const int ch : e.channels) out.row(ch) = out.row(ch).cwiseMax(-lim).cwiseMin(lim);
    }
  }
  return out;
}

void InsertOverload(const Effect& e, LoadProfile& profile, const Wrench& rated) {
  const double t = e.num.at("onset_s");
  Wrench over = Wrench::Zero();
  over(e.axis) = e.num.at("factor") * rated(e.axis);
  profile.Splice(t - 0.7, t + 1.4, {t - 0.5, t - 0.3, t, t + 0.3, t + 0.6, t + 1.2},
                 {Wrench::Zero(), Wrench::Zero(), over, over, Wrench::Zero(), Wrench::Zero()});
}

}  // namespace ftstack::sim
