#include "sim/load_profile.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "measurement/recording.hpp"
#include "sim/work_cycles.hpp"

namespace ftstack::sim {

std::uint64_t SeededRandom::Next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double SeededRandom::Uniform(double lo, double hi) {
  const double u = static_cast<double>(Next() >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

double SeededRandom::Normal() {
  double u1 = Uniform();
  while (u1 <= 0.0) u1 = Uniform();
  const double u2 = Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

int SeededRandom::Index(int n) { return static_cast<int>(Next() % static_cast<std::uint64_t>(n)); }

namespace {

double Interp(const std::vector<double>& t, const std::vector<double>& v, double x) {
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  const auto it = std::upper_bound(t.begin(), t.end(), x);
  const std::size_t b = static_cast<std::size_t>(it - t.begin());
  const double f = (x - t[b - 1]) / (t[b] - t[b - 1]);
  return v[b - 1] + f * (v[b] - v[b - 1]);
}

// Appends keyframes as a sequence of ramps and holds.
class Builder {
 public:
  void Ramp(const Wrench& to, double dur_s) {
    t_ += dur_s;
    Key(to);
  }
  void Hold(double dur_s) { Ramp(w_, dur_s); }
  [[nodiscard]] double t() const { return t_; }
  [[nodiscard]] const Wrench& w() const { return w_; }
  void Start() {
    if (ts_.empty()) {
      ts_.push_back(0.0);
      ws_.push_back(Wrench::Zero());
    }
  }
  std::vector<double> ts_;
  std::vector<Wrench> ws_;

 private:
  void Key(const Wrench& to) {
    w_ = to;
    ts_.push_back(t_);
    ws_.push_back(to);
  }
  double t_ = 0.0;
  Wrench w_ = Wrench::Zero();
};

// Load applied over `edge_s`, held, removed over `edge_s`, then rest unloaded.
void Pulse(Builder& b, const Wrench& w, double edge_s, double hold_s, double rest_s) {
  b.Ramp(w, edge_s);
  b.Hold(hold_s);
  b.Ramp(Wrench::Zero(), edge_s);
  b.Hold(rest_s);
}

Wrench Axis(int k, double v) {
  Wrench w = Wrench::Zero();
  w(k) = v;
  return w;
}

void AxisSection(Builder& b, const Wrench& r, SeededRandom& rng, int k) {
  const double a = rng.Uniform(0.6, 0.9) * r(k);
  for (const double s : {1.0, -1.0}) {  // steps
    const double hold = rng.Uniform(2.0, 3.0);
    Pulse(b, Axis(k, s * a), 0.4, hold, rng.Uniform(1.5, 2.5));
  }
  for (const double s : {1.0, -1.0}) {  // up/down staircase: same loads from below and above
    for (const double f : {1.0 / 3.0, 2.0 / 3.0, 1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0}) {
      b.Ramp(Axis(k, s * f * a), 0.3);
      b.Hold(rng.Uniform(0.8, 1.2));
    }
  }
}

// Axial preload combined with each shear force and bending moment.
void PreloadSection(Builder& b, const Wrench& r, SeededRandom& rng, double sign) {
  const Wrench pre = Axis(2, sign * rng.Uniform(0.5, 0.7) * r(2));
  b.Ramp(pre, 0.5);
  b.Hold(1.0);
  for (const int k : {0, 1, 3, 4}) {
    for (const double sk : {1.0, -1.0}) {
      b.Ramp(pre + Axis(k, sk * rng.Uniform(0.4, 0.6) * r(k)), 0.4);
      b.Hold(rng.Uniform(1.0, 1.4));
      b.Ramp(pre, 0.4);
      b.Hold(0.5);
    }
  }
  b.Ramp(Wrench::Zero(), 0.5);
  b.Hold(2.0);
}

// Fast taps (5 ms edges).
void TapSection(Builder& b, const Wrench& r, SeededRandom& rng, int count) {
  for (int i = 0; i < count; ++i) {
    const int k = rng.Index(6);
    const double s = rng.Uniform() < 0.5 ? -1.0 : 1.0;
    const Wrench w = Axis(k, s * rng.Uniform(0.3, 0.6) * r(k));
    const double hold = rng.Uniform(0.3, 0.6);
    Pulse(b, w, 0.005, hold, rng.Uniform(1.0, 1.5));
  }
}

// One rig cycle (≈ 250 s). Sections alternate so that a record cut short still holds steps,
// sweeps, preload × moment combinations and taps.
void RigCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  b.Start();
  b.Hold(3.0);
  std::vector<int> order = {0, 1, 2, 3, 4, 5};
  for (int i = 5; i > 0; --i) {
    std::swap(order[static_cast<std::size_t>(i)],
              order[static_cast<std::size_t>(rng.Index(i + 1))]);
  }
  for (int i = 0; i < 3; ++i) AxisSection(b, r, rng, order[static_cast<std::size_t>(i)]);
  PreloadSection(b, r, rng, 1.0);
  TapSection(b, r, rng, 4);
  for (int i = 3; i < 6; ++i) AxisSection(b, r, rng, order[static_cast<std::size_t>(i)]);
  PreloadSection(b, r, rng, -1.0);
  for (int i = 0; i < 6; ++i) {  // random combined wrenches
    Wrench w;
    for (int k = 0; k < 6; ++k) w(k) = rng.Uniform(-0.6, 0.6) * r(k);
    Pulse(b, w, 0.6, rng.Uniform(1.2, 1.8), 1.0);
  }
  TapSection(b, r, rng, 4);
  b.Hold(3.0);
}

void TapsCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  b.Start();
  b.Hold(2.0);
  while (b.t() < 58.0) {
    Wrench w = Wrench::Zero();
    const int k = rng.Index(6);
    w(k) = (rng.Uniform() < 0.5 ? -1.0 : 1.0) * rng.Uniform(0.2, 0.7) * r(k);
    if (rng.Uniform() < 0.3) {  // some combined taps
      const int k2 = rng.Index(6);
      w(k2) += rng.Uniform(-0.4, 0.4) * r(k2);
    }
    const double hold = rng.Uniform(0.4, 1.2);
    Pulse(b, w, 0.005, hold, rng.Uniform(0.5, 1.5));
  }
}

void HoldCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  b.Start();
  b.Hold(5.0);
  const std::vector<std::pair<int, double>> loads = {
      {2, 0.7}, {0, 0.6}, {3, -0.6}, {4, 0.6}, {2, -0.5}};
  for (const auto& [k, f] : loads) {
    Wrench w = Axis(k, f * rng.Uniform(0.85, 1.0) * r(k));
    if (rng.Uniform() < 0.4) w(5) = rng.Uniform(-0.3, 0.3) * r(5);
    const double hold = rng.Uniform(40.0, 60.0);
    Pulse(b, w, 0.5, hold, rng.Uniform(40.0, 60.0));
  }
}

// A sensor under a robot's base (issue 13). Loads are fractions of the rated range per axis: on
// a sensor rated at the Panda base figures (300 N, 300 N, 410 N, 280, 280, 190 N·m) they are
// those figures. The arm's weight presses down (Fz < 0, 43 % of rated); reaching out tilts.
Wrench Scaled(const Wrench& frac, const Wrench& r) { return frac.cwiseProduct(r); }

Wrench BaseStatic() { return Axis(2, -0.43); }

// Reach in direction a (rad): lateral force along a, tilting moment about the perpendicular axis.
Wrench Reach(double a, double f_xy, double f_z, double m_xy, double m_z) {
  Wrench w = Wrench::Zero();
  w << f_xy * std::cos(a), f_xy * std::sin(a), -f_z, -m_xy * std::sin(a), m_xy * std::cos(a), m_z;
  return w;
}

// Pick-and-place: four reach-pick-return moves in random directions, combined share < 0.9.
void BasePickCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  b.Start();
  b.Ramp(Scaled(BaseStatic(), r), 1.0);
  b.Hold(1.0);
  for (int i = 0; i < 4; ++i) {
    const double a = rng.Uniform(0.0, 2.0 * std::numbers::pi);
    const double mz = rng.Uniform(-0.2, 0.2);
    b.Ramp(Scaled(Reach(a, 0.25, 0.53, 0.35, mz), r), 0.6);
    b.Hold(0.4);
    b.Ramp(Scaled(BaseStatic(), r), 0.6);
    b.Hold(0.5);
  }
}

// Slow tilting: the arm reaches out and holds (tilt share 0.55: inside the rating).
void BaseTiltCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  b.Start();
  b.Ramp(Scaled(BaseStatic(), r), 1.0);
  for (int i = 0; i < 2; ++i) {
    const double a = rng.Uniform(0.0, 2.0 * std::numbers::pi);
    b.Ramp(Scaled(Reach(a, 0.05, 0.45, 0.55, 0.0), r), 4.0);
    b.Hold(3.0);
    b.Ramp(Scaled(BaseStatic(), r), 4.0);
    b.Hold(1.0);
  }
}

// Emergency stop during a fast move: within 20 ms every component reaches its rated value (the
// Panda figures all at once: combined share 2, an overload), then rings down at 8 Hz (halving
// each half period) to the static load.
void BaseEstopCycle(Builder& b, const Wrench& r, SeededRandom& rng) {
  BasePickCycle(b, r, rng);
  const double a = rng.Uniform(0.0, 2.0 * std::numbers::pi);
  b.Ramp(Scaled(Reach(a, 0.3, 0.5, 0.3, 0.2), r), 0.3);
  const Wrench base = Scaled(BaseStatic(), r);
  const Wrench peak = Scaled(Reach(a, 1.0, 1.0, 1.0, 1.0), r);
  b.Ramp(peak, 0.02);
  b.Hold(0.03);
  double amp = -0.5;
  for (int i = 0; i < 6; ++i, amp *= -0.5) b.Ramp(base + amp * (peak - base), 1.0 / 16.0);
  b.Ramp(base, 0.1);
  b.Hold(3.0);
}

using CycleFn = void (*)(Builder&, const Wrench&, SeededRandom&);

// Lab temperature: a slow wander of ±0.4 K around 22 °C.
void LabTemperature(double duration_s, SeededRandom& rng, std::vector<double>& tt,
                    std::vector<double>& tc) {
  const double phase = rng.Uniform(0.0, 2.0 * std::numbers::pi);
  const double period = rng.Uniform(600.0, 1200.0);
  for (double t = 0.0;; t += 1.0) {
    tt.push_back(t);
    tc.push_back(22.0 + 0.4 * std::sin(2.0 * std::numbers::pi * t / period + phase) -
                 0.4 * std::sin(phase));
    if (t >= duration_s) break;
  }
}

LoadProfile Generated(const std::string& name, CycleFn cycle, double rate_hz, const Wrench& r,
                      std::uint64_t seed, double duration_s, bool thermal) {
  SeededRandom rng(seed * 0x2545F4914F6CDD1DULL + 0x51ED2701ULL);
  Builder b;
  cycle(b, r, rng);
  while (duration_s > 0.0 && b.t() < duration_s) cycle(b, r, rng);
  const double dur = duration_s > 0.0 ? duration_s : b.t();
  std::vector<double> tt;
  std::vector<double> tc;
  if (!thermal) {
    LabTemperature(dur, rng, tt, tc);
  } else {
    // Ambient rise of ≈ 6 K (first order, τ = half the record) plus self-heating of up to 2 K from
    // the rig's actuators, following the load intensity through a 90 s thermal lag.
    const double amb = rng.Uniform(5.0, 7.0);
    const double tau_amb = 0.5 * dur;
    double heat = 0.0;
    const double dt = 0.5;
    const double a = std::exp(-dt / 90.0);
    const LoadProfile loads(name, b.ts_, b.ws_, {0.0}, {20.0}, dur, rate_hz);
    for (double t = 0.0;; t += dt) {
      const Wrench w = loads.LoadAt(t);
      double intensity = 0.0;
      for (int k = 0; k < 6; ++k) intensity += std::abs(w(k)) / r(k);
      heat = a * heat + (1.0 - a) * std::min(intensity, 1.5);
      tt.push_back(t);
      tc.push_back(20.0 + amb * (1.0 - std::exp(-t / tau_amb)) + 2.0 * heat / 1.5);
      if (t >= dur) break;
    }
  }
  return LoadProfile(name, b.ts_, b.ws_, tt, tc, dur, rate_hz);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProfileError(path + ": cannot open profile");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// "line:column" (1-based) of the byte at 1-based offset `byte`, as nlohmann's parse_error gives it.
std::string LineColumn(const std::string& text, std::size_t byte) {
  const std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  const auto first = text.begin();
  const auto lines = std::count(first, first + static_cast<std::ptrdiff_t>(end), '\n');
  const std::size_t nl = text.rfind('\n', end > 0 ? end - 1 : 0);
  const std::size_t col = (nl == std::string::npos || end == 0) ? end + 1 : end - nl;
  return std::to_string(lines + 1) + ":" + std::to_string(col);
}

// Byte offsets (0-based) where each element of the top-level object's array `key` starts, found
// by a scan that skips strings; the text has already parsed as JSON. Empty if not found.
std::vector<std::size_t> ArrayElementOffsets(const std::string& text, const std::string& key) {
  std::vector<std::size_t> out;
  int depth = 0;
  bool in_array = false;  // inside the wanted array (at depth 2)
  bool expect_element = false;
  std::string last_string;
  bool key_seen = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') continue;
    if (expect_element && c != ']') {
      out.push_back(i);
      expect_element = false;
    }
    if (c == '"') {
      const std::size_t start = i + 1;
      for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (text[i] == '\\') ++i;
      }
      last_string = text.substr(start, i - start);
      continue;
    }
    if (c == ':' && depth == 1) key_seen = last_string == key;
    if (c == '{' || c == '[') {
      ++depth;
      if (c == '[' && depth == 2 && key_seen) {
        in_array = true;
        expect_element = true;
      }
    } else if (c == '}' || c == ']') {
      if (in_array && depth == 2) return out;
      --depth;
    } else if (c == ',' && in_array && depth == 2) {
      expect_element = true;
    }
  }
  return out;
}

LoadProfile KeyframesFromJson(const std::string& text, const std::string& path, double duration_s) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw ProfileError(path + ":" + LineColumn(text, e.byte) + ": not valid JSON");
  } catch (const nlohmann::json::exception& e) {  // e.g. a number beyond double (found by fuzzing)
    throw ProfileError(path + ": not valid JSON: " + e.what());
  }
  if (!j.is_object() || !j.contains("schema") || !j["schema"].is_string() ||
      j["schema"].get<std::string>() != "ftstack-profile/1") {
    throw ProfileError(path + ": schema is not 'ftstack-profile/1'");
  }
  if (!j.contains("keyframes") || !j["keyframes"].is_array() || j["keyframes"].empty()) {
    throw ProfileError(path + ": 'keyframes' must be a non-empty array");
  }
  // `what` starts with ": name" or ":LINE:COLUMN: name".
  auto num = [&](const nlohmann::json& v, const std::string& what) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw ProfileError(path + what + " is not a finite number");
    }
    return v.get<double>();
  };
  std::vector<double> lt;
  std::vector<Wrench> lw;
  std::vector<double> tt;
  std::vector<double> tc;
  const std::vector<std::size_t> offsets = ArrayElementOffsets(text, "keyframes");
  std::size_t i = 0;
  for (const auto& k : j["keyframes"]) {
    // "PATH:LINE:COLUMN: keyframes[i]" (the keyframe's opening brace), or without the position.
    const std::string at = i < offsets.size() && offsets.size() == j["keyframes"].size()
                               ? ":" + LineColumn(text, offsets[i] + 1)
                               : "";
    const std::string where = at + ": keyframes[" + std::to_string(i++) + "]";
    if (!k.is_object() || !k.contains("t_s") || !k.contains("wrench")) {
      throw ProfileError(path + where + " needs 't_s' and 'wrench'");
    }
    const double t = num(k["t_s"], where + ".t_s");
    if (!lt.empty() && !(t > lt.back())) {
      throw ProfileError(path + where + ".t_s does not increase");
    }
    const auto& wj = k["wrench"];
    if (!wj.is_array() || wj.size() != 6) {
      throw ProfileError(path + where + ".wrench needs 6 numbers Fx,Fy,Fz,Mx,My,Mz");
    }
    Wrench w;
    for (std::size_t c = 0; c < 6; ++c) w(static_cast<int>(c)) = num(wj[c], where + ".wrench");
    lt.push_back(t);
    lw.push_back(w);
    if (k.contains("temp_C")) {
      tt.push_back(t);
      tc.push_back(num(k["temp_C"], where + ".temp_C"));
    }
  }
  const double t0 = lt.front();
  for (double& t : lt) t -= t0;
  for (double& t : tt) t -= t0;
  // Finite times can still span more than a double holds (-1e308 … 1e308).
  if (!std::isfinite(lt.back())) {
    throw ProfileError(path + ": keyframe times span more than a finite duration");
  }
  if (tt.empty()) {
    tt.push_back(0.0);
    tc.push_back(20.0);
  }
  double rate = 200.0;
  if (j.contains("rate_hz")) {
    rate = num(j["rate_hz"], ": rate_hz");
    if (rate <= 0.0) throw ProfileError(path + ": rate_hz must be positive");
  }
  const double dur = duration_s > 0.0 ? duration_s : lt.back();
  if (!(dur > 0.0)) throw ProfileError(path + ": profile has zero duration");
  return LoadProfile(path, lt, lw, tt, tc, dur, rate);
}

LoadProfile FromCsv(const std::string& path, double duration_s) {
  ReadOptions opt;
  opt.required = {"t"};
  opt.require_wrench = true;
  Recording rec;
  try {
    rec = ReadRecording(path, opt);
  } catch (const RecordingError& e) {
    throw ProfileError(e.what());
  }
  if (rec.rows() < 2) throw ProfileError(path + ": a profile needs at least 2 rows");
  const auto& t = rec.Column("t");
  std::vector<double> lt(t.size());
  std::vector<Wrench> lw(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    lt[i] = t[i] - t[0];
    for (int k = 0; k < 6; ++k)
      lw[i](k) = rec.Column(WrenchColumns()[static_cast<std::size_t>(k)])[i];
  }
  std::vector<double> tc = rec.Has("temp_C") ? rec.Column("temp_C") : std::vector<double>{20.0};
  std::vector<double> tt = rec.Has("temp_C") ? lt : std::vector<double>{0.0};
  const double rate = static_cast<double>(t.size() - 1) / lt.back();
  const double dur = duration_s > 0.0 ? duration_s : lt.back();
  return LoadProfile(path, lt, lw, tt, tc, dur, rate);
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

LoadProfile::LoadProfile(std::string name, std::vector<double> load_t_s, std::vector<Wrench> load,
                         std::vector<double> temp_t_s, std::vector<double> temp_c,
                         double duration_s, double default_rate_hz)
    : name_(std::move(name)),
      load_t_(std::move(load_t_s)),
      load_(std::move(load)),
      temp_t_(std::move(temp_t_s)),
      temp_c_(std::move(temp_c)),
      duration_s_(duration_s),
      default_rate_hz_(default_rate_hz) {
  if (load_t_.empty() || load_t_.size() != load_.size() || temp_t_.empty() ||
      temp_t_.size() != temp_c_.size()) {
    throw ProfileError(name_ + ": profile needs load and temperature keyframes");
  }
  for (std::size_t i = 1; i < load_t_.size(); ++i) {
    if (!(load_t_[i] > load_t_[i - 1]))
      throw ProfileError(name_ + ": keyframe times must increase");
  }
}

namespace {

Wrench InterpWrench(const std::vector<double>& t, const std::vector<Wrench>& w, double t_s) {
  if (t_s <= t.front()) return w.front();
  if (t_s >= t.back()) return w.back();
  const auto it = std::upper_bound(t.begin(), t.end(), t_s);
  const std::size_t b = static_cast<std::size_t>(it - t.begin());
  const double f = (t_s - t[b - 1]) / (t[b] - t[b - 1]);
  return w[b - 1] + f * (w[b] - w[b - 1]);
}

}  // namespace

Wrench LoadProfile::LoadAt(double t_s) const {
  Wrench w = InterpWrench(load_t_, load_, t_s);
  if (!vibration_t_.empty()) {
    w += InterpWrench(vibration_t_, vibration_, t_s) *
         std::sin(2.0 * std::numbers::pi * vibration_hz_ * t_s);
  }
  return w;
}

void LoadProfile::SetVibration(double freq_hz, std::vector<double> amplitude_t_s,
                               std::vector<Wrench> amplitude) {
  if (!(freq_hz > 0) || amplitude_t_s.empty() || amplitude_t_s.size() != amplitude.size()) {
    throw ProfileError(name_ + ": a vibration needs a frequency > 0 and amplitude keyframes");
  }
  vibration_hz_ = freq_hz;
  vibration_t_ = std::move(amplitude_t_s);
  vibration_ = std::move(amplitude);
}

double LoadProfile::TemperatureAt(double t_s) const { return Interp(temp_t_, temp_c_, t_s); }

void LoadProfile::Splice(double t0_s, double t1_s, const std::vector<double>& t_s,
                         const std::vector<Wrench>& w) {
  const Wrench w0 = LoadAt(t0_s);
  const Wrench w1 = LoadAt(t1_s);
  std::vector<double> nt;
  std::vector<Wrench> nw;
  for (std::size_t i = 0; i < load_t_.size(); ++i) {
    if (load_t_[i] < t0_s) {
      nt.push_back(load_t_[i]);
      nw.push_back(load_[i]);
    }
  }
  nt.push_back(t0_s);
  nw.push_back(w0);
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    if (t_s[i] > nt.back() && t_s[i] < t1_s) {
      nt.push_back(t_s[i]);
      nw.push_back(w[i]);
    }
  }
  nt.push_back(t1_s);
  nw.push_back(w1);
  for (std::size_t i = 0; i < load_t_.size(); ++i) {
    if (load_t_[i] > t1_s) {
      nt.push_back(load_t_[i]);
      nw.push_back(load_[i]);
    }
  }
  load_t_ = std::move(nt);
  load_ = std::move(nw);
}

LoadProfile ParseProfileJson(const std::string& text, const std::string& path, double duration_s) {
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) {
    throw ProfileError("duration must be a finite number >= 0");
  }
  try {
    return KeyframesFromJson(text, path, duration_s);
  } catch (const nlohmann::json::exception& e) {  // a value of the wrong JSON type anywhere
    throw ProfileError(path + ": " + e.what());
  }
}

LoadProfile MakeProfile(const std::string& spec, const Wrench& rated, std::uint64_t seed,
                        double duration_s) {
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) {
    throw ProfileError("duration must be a finite number >= 0");
  }
  if (spec == "rig") return Generated("rig", RigCycle, 200.0, rated, seed, duration_s, false);
  if (spec == "taps") return Generated("taps", TapsCycle, 200.0, rated, seed, duration_s, false);
  if (spec == "thermal")
    return Generated("thermal", RigCycle, 200.0, rated, seed, duration_s, true);
  if (spec == "hold") return Generated("hold", HoldCycle, 100.0, rated, seed, duration_s, false);
  if (spec == "base-pick") {
    return Generated("base-pick", BasePickCycle, 200.0, rated, seed, duration_s, false);
  }
  if (spec == "base-tilt") {
    return Generated("base-tilt", BaseTiltCycle, 200.0, rated, seed, duration_s, false);
  }
  if (spec == "base-estop") {
    return Generated("base-estop", BaseEstopCycle, 1000.0, rated, seed, duration_s, false);
  }
  if (spec.rfind("work:", 0) == 0) return MakeWorkCycle(spec.substr(5), rated, seed, duration_s);
  std::string path = spec;
  if (path.rfind("file:", 0) == 0) path = path.substr(5);
  if (EndsWith(path, ".json")) {
    return ParseProfileJson(ReadText(path), path, duration_s);
  }
  if (EndsWith(path, ".csv")) return FromCsv(path, duration_s);
  throw ProfileError("unknown profile '" + spec +
                     "' (rig, taps, thermal, hold, base-pick, base-tilt, base-estop, or a .json "
                     "keyframe / .csv recording file, or work:NAME)");
}

}  // namespace ftstack::sim
