#include "sim/work_cycles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>

namespace ftstack::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDay = 86400.0;

/// Keyframes appended in time order; a key at or before the last one is moved just after it.
class Keys {
 public:
  void At(double t, const Wrench& w) {
    if (!t_.empty() && t <= t_.back()) t = t_.back() + 1e-3;
    t_.push_back(t);
    w_.push_back(w);
  }
  [[nodiscard]] double last() const { return t_.empty() ? 0.0 : t_.back(); }
  std::vector<double> t_;
  std::vector<Wrench> w_;
};

Wrench W(double fx, double fy, double fz, double mx, double my, double mz) {
  Wrench w;
  w << fx, fy, fz, mx, my, mz;
  return w;
}

/// A part of weight g (N) held at r (m) from the sensor, tilted by th about x: its wrench.
Wrench Held(double g, const std::array<double, 3>& r, double th, double push) {
  const double fy = g * std::sin(th);
  const double fz = -g * std::cos(th);
  return W(0, fy, fz + push, r[1] * (fz + push) - r[2] * fy, -r[0] * (fz + push), r[0] * fy);
}

double MachineTending(Keys& k, const Wrench& r, SeededRandom& rng, double t0) {
  const double g = rng.Uniform(0.1, 0.2) * r(2);
  const std::array<double, 3> at = {rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05),
                                    rng.Uniform(0.01, 0.05)};
  const double turn_at = rng.Uniform(2.5, 5.0);
  const double turn_s = rng.Uniform(1.0, 2.0);
  const double theta = rng.Uniform(20.0, 60.0) * kPi / 180.0;
  const double press_at = rng.Uniform(7.0, 9.0);
  const double release = press_at + rng.Uniform(0.5, 1.5);
  const double push = 0.375 * r(2);
  k.At(t0, Wrench::Zero());
  k.At(t0 + 0.01, Held(g, at, 0, 0));
  for (int i = 0; i <= 8; ++i) {
    k.At(t0 + turn_at + turn_s * i / 8.0,
         Held(g, at, theta * (0.5 - 0.5 * std::cos(kPi * i / 8.0)), 0));
  }
  k.At(t0 + press_at, Held(g, at, theta, 0));
  k.At(t0 + press_at + 0.01, Held(g, at, theta, push));
  k.At(t0 + press_at + 0.3, Held(g, at, theta, push));
  k.At(t0 + press_at + 0.31, Held(g, at, theta, 0));
  k.At(t0 + release, Held(g, at, theta, 0));
  k.At(t0 + release + 0.01, Wrench::Zero());
  return t0 + release + rng.Uniform(3.0, 12.0);
}

double Palletising(Keys& k, const Wrench& r, SeededRandom& rng, double t0) {
  const double g = rng.Uniform(0.25, 0.6) * r(2);
  const std::array<double, 3> at = {rng.Uniform(-0.03, 0.03), rng.Uniform(-0.03, 0.03), 0.1};
  const double carry = rng.Uniform(10.0, 30.0);
  k.At(t0, Wrench::Zero());
  double t = t0 + 0.3;
  k.At(t, Held(g, at, 0, 0));
  // The swing of the carry: lateral inertia of ±3 % of the weight, changing every 2–4 s.
  while (t < t0 + 0.3 + carry - 4.0) {
    t += rng.Uniform(2.0, 4.0);
    Wrench w = Held(g, at, 0, 0);
    const double ax = rng.Uniform(-0.03, 0.03) * g;
    const double ay = rng.Uniform(-0.03, 0.03) * g;
    w += W(ax, ay, 0, -0.1 * ay, 0.1 * ax, 0);
    k.At(t, w);
  }
  k.At(t0 + 0.3 + carry, Held(g, at, 0, 0));
  k.At(t0 + 0.6 + carry, Wrench::Zero());
  return t0 + 0.6 + carry + rng.Uniform(5.0, 10.0);
}

double Assembly(Keys& k, const Wrench& r, SeededRandom& rng, double t0) {
  const double part = rng.Uniform(0.01, 0.03) * r(2);
  const double contact = rng.Uniform(0.05, 0.15) * r(2);
  const double insert = rng.Uniform(0.1, 0.2) * r(2);
  k.At(t0, Wrench::Zero());
  k.At(t0 + 0.2, W(0, 0, -part, 0, 0, 0));
  double t = t0 + rng.Uniform(1.5, 2.5);
  k.At(t, W(0, 0, -part, 0, 0, 0));
  // Contact: a 5 ms edge, then a bounce halving every 15 ms.
  double a = contact;
  for (int i = 0; i < 6; ++i, a *= -0.5) {
    t += i == 0 ? 0.005 : 0.015;
    k.At(t, W(0, 0, -part + a, 0, 0, 0));
  }
  // Insertion: force builds up over 0.5–1 s with lateral jitter from the chamfer.
  const double ins_s = rng.Uniform(0.5, 1.0);
  const double start = t;
  for (int i = 1; i <= 10; ++i) {
    const double fx = rng.Uniform(-0.02, 0.02) * r(0);
    const double fy = rng.Uniform(-0.02, 0.02) * r(1);
    k.At(start + ins_s * i / 10.0, W(fx, fy, -part + insert * i / 10.0, -0.02 * fy, 0.02 * fx, 0));
  }
  t = start + ins_s + rng.Uniform(0.2, 0.5);
  k.At(t, W(0, 0, -part + insert, 0, 0, 0));
  k.At(t + 0.05, Wrench::Zero());
  return t + rng.Uniform(2.5, 5.0);
}

double Screwdriving(Keys& k, const Wrench& r, SeededRandom& rng, double t0) {
  const int screws = 4 + rng.Index(5);
  double t = t0;
  k.At(t, Wrench::Zero());
  for (int s = 0; s < screws; ++s) {
    const double push = rng.Uniform(0.075, 0.2) * r(2);
    const double torque = rng.Uniform(0.25, 0.75) * r(5);
    const double build = rng.Uniform(0.3, 0.8);
    t += rng.Uniform(1.0, 2.0);
    k.At(t, Wrench::Zero());
    k.At(t + 0.2, W(0, 0, push, 0, 0, 0));
    k.At(t + 0.2 + rng.Uniform(0.5, 1.5), W(0, 0, push, 0, 0, 0.1 * torque));
    t = k.last() + build;
    k.At(t, W(0, 0, push, 0, 0, torque));
    k.At(t + 0.005, W(0, 0, push, 0, 0, 0));
    k.At(t + 0.2, Wrench::Zero());
    t += 0.2;
  }
  return t + rng.Uniform(8.0, 12.0);
}

double HandGuiding(Keys& k, const Wrench& r, SeededRandom& rng, double t0) {
  const double session = rng.Uniform(600.0, 1800.0);
  double t = t0;
  k.At(t, Wrench::Zero());
  Wrench w = Wrench::Zero();
  // A bounded random walk of every axis, a new target every 0.3–0.8 s: never held.
  while (t < t0 + session) {
    t += rng.Uniform(0.3, 0.8);
    for (int a = 0; a < 6; ++a) {
      w(a) = std::clamp(w(a) + rng.Uniform(-0.04, 0.04) * r(a), -0.15 * r(a), 0.15 * r(a));
    }
    k.At(t, w);
  }
  k.At(t + 0.5, Wrench::Zero());
  return t + 0.5 + rng.Uniform(60.0, 300.0);
}

double NightIdle(Keys& k, const Wrench& /*r*/, SeededRandom& /*rng*/, double t0) {
  k.At(t0, Wrench::Zero());
  return t0 + 3600.0;
}

/// Polishing: the contact passes as keyframes; the spindle's vibration as its amplitude.
double Polishing(Keys& k, Keys& vib, const Wrench& r, SeededRandom& rng, double t0) {
  const double force = rng.Uniform(0.075, 0.15) * r(2);
  const double pass = rng.Uniform(20.0, 60.0);
  const Wrench idle_vib = W(0.002 * r(0), 0.002 * r(1), 0.002 * r(2), 0, 0, 0);
  const Wrench contact_vib =
      W(0.01 * r(0), 0.01 * r(1), 0.01 * r(2), 0.005 * r(3), 0.005 * r(4), 0);
  k.At(t0, Wrench::Zero());
  vib.At(t0, idle_vib);
  double t = t0 + 0.5;
  k.At(t, W(0, 0, force, 0, 0, 0));
  vib.At(t, contact_vib);
  while (t < t0 + pass) {
    t += rng.Uniform(0.5, 1.5);
    const double f = force * rng.Uniform(0.9, 1.1);
    const double dir = rng.Uniform(0.0, 2.0 * kPi);
    const double mu = 0.3 * f;
    k.At(t, W(mu * std::cos(dir), mu * std::sin(dir), f, -0.05 * mu * std::sin(dir),
              0.05 * mu * std::cos(dir), 0));
  }
  vib.At(t, contact_vib);
  k.At(t + 0.5, Wrench::Zero());
  vib.At(t + 0.5, idle_vib);
  return t + 0.5 + rng.Uniform(2.0, 5.0);
}

using Cycle = std::function<double(Keys&, Keys&, const Wrench&, SeededRandom&, double)>;

Cycle Plain(double (*f)(Keys&, const Wrench&, SeededRandom&, double)) {
  return [f](Keys& k, Keys& /*vib*/, const Wrench& r, SeededRandom& rng, double t) {
    return f(k, r, rng, t);
  };
}

/// Body temperature of each cycle's day (°C at t_s).
double Temperature(const std::string& name, double t, double phase) {
  const double day = std::sin(kPi * std::fmod(t, kDay) / kDay);  // 0 → 1 → 0 over a day
  if (name == "machine-tending") return 19.0 + 8.0 * day;
  if (name == "palletising") return 15.0 + 7.0 * day;
  if (name == "polishing") return 22.0 + 6.0 * (1.0 - std::exp(-t / 1800.0)) + day;
  if (name == "night-idle") {
    const double period = 2.0 * 3600.0 + 2.0 * 3600.0 * (0.5 + 0.5 * std::sin(phase));
    return 22.0 - 4.0 * std::cos(2.0 * kPi * t / period) +
           0.5 * std::sin(2.0 * kPi * t / 1200.0 + phase) - 0.5 * std::sin(phase);
  }
  if (name == "screwdriving") return 21.0 + 3.0 * day;
  return 21.0 + 2.0 * day;
}

}  // namespace

const std::vector<std::string>& WorkCycleNames() {
  static const std::vector<std::string> names = {"machine-tending", "palletising",  "assembly",
                                                 "polishing",       "hand-guiding", "screwdriving",
                                                 "night-idle"};
  return names;
}

LoadProfile MakeWorkCycle(const std::string& name, const Wrench& rated, std::uint64_t seed,
                          double duration_s) {
  Cycle cycle;
  if (name == "machine-tending") cycle = Plain(MachineTending);
  if (name == "palletising") cycle = Plain(Palletising);
  if (name == "assembly") cycle = Plain(Assembly);
  if (name == "screwdriving") cycle = Plain(Screwdriving);
  if (name == "hand-guiding") cycle = Plain(HandGuiding);
  if (name == "night-idle") cycle = Plain(NightIdle);
  if (name == "polishing") cycle = Polishing;
  if (!cycle) {
    std::string known;
    for (const auto& n : WorkCycleNames()) known += (known.empty() ? "" : ", ") + n;
    throw ProfileError("unknown work cycle '" + name + "' (" + known + ")");
  }
  const double dur = duration_s > 0.0 ? duration_s : kDay;
  SeededRandom rng(seed * 0x9E3779B97F4A7C15ULL + 0x7F4A7C15ULL);
  Keys keys;
  Keys vib;
  double t = 1.0;
  keys.At(0.0, Wrench::Zero());
  while (t < dur) t = cycle(keys, vib, rated, rng, t);
  const double phase = rng.Uniform(0.0, 2.0 * kPi);
  std::vector<double> tt;
  std::vector<double> tc;
  for (double s = 0.0;; s += 60.0) {
    tt.push_back(std::min(s, dur));
    tc.push_back(Temperature(name, tt.back(), phase));
    if (s >= dur) break;
  }
  LoadProfile profile("work:" + name, keys.t_, keys.w_, tt, tc, dur, 1000.0);
  if (!vib.t_.empty()) profile.SetVibration(rng.Uniform(110.0, 190.0), vib.t_, vib.w_);
  return profile;
}

}  // namespace ftstack::sim
