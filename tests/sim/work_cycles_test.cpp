// The work cycles: what each one is said to be, checked on the generated day.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "sim/load_profile.hpp"
#include "sim/work_cycles.hpp"

namespace ftstack::sim {
namespace {

Wrench Rated() {
  Wrench r;
  r << 200, 200, 400, 10, 10, 8;
  return r;
}

/// Largest |load| per axis and the temperature range, sampled every step_s over [t0, t1).
struct Extent {
  Wrench peak = Wrench::Zero();
  double t_min = 1e9;
  double t_max = -1e9;
  double longest_still_s = 0.0;  // longest run with every axis within 0.1 % of rated of its start
};

Extent Scan(const LoadProfile& p, const Wrench& r, double t0, double t1, double step_s = 1e-3) {
  Extent e;
  Wrench held = p.LoadAt(t0);
  double since = t0;
  for (double t = t0; t < t1; t += step_s) {
    const Wrench w = p.LoadAt(t);
    e.peak = e.peak.cwiseMax(w.cwiseAbs());
    e.t_min = std::min(e.t_min, p.TemperatureAt(t));
    e.t_max = std::max(e.t_max, p.TemperatureAt(t));
    if (((w - held).cwiseAbs().array() > 1e-3 * r.array()).any()) {
      held = w;
      since = t;
    }
    e.longest_still_s = std::max(e.longest_still_s, t - since);
  }
  return e;
}

TEST(WorkCycles, EveryCycleIsADayDeterministicPerSeedAndWithinRated) {
  const Wrench r = Rated();
  for (const std::string& name : WorkCycleNames()) {
    const LoadProfile a = MakeWorkCycle(name, r, 5, 0.0);
    const LoadProfile b = MakeProfile("work:" + name, r, 5, 0.0);
    const LoadProfile c = MakeWorkCycle(name, r, 6, 0.0);
    EXPECT_EQ(a.duration_s(), 86400.0) << name;
    EXPECT_EQ(a.default_rate_hz(), 1000.0) << name;
    EXPECT_EQ(a.key_times_s(), b.key_times_s()) << name;
    const Extent e = Scan(a, r, 3600.0, 3900.0);
    EXPECT_TRUE((e.peak.array() <= r.array()).all()) << name << ": " << e.peak.transpose();
    if (name != "night-idle") {
      EXPECT_NE(a.key_loads().size() > 10 ? a.key_times_s()[10] : 0.0, c.key_times_s()[10])
          << name << ": another seed, another day";
    }
  }
  EXPECT_THROW((void)MakeWorkCycle("welding", r, 1, 0.0), ProfileError);
  EXPECT_THROW((void)MakeProfile("work:welding", r, 1, 0.0), ProfileError);
}

TEST(WorkCycles, EachCycleHasItsCharacter) {
  const Wrench r = Rated();
  // Hand guiding: moving all the time during a session (no 1 s still), on every axis.
  const LoadProfile guide = MakeWorkCycle("hand-guiding", r, 2, 0.0);
  const Extent g = Scan(guide, r, 10.0, 300.0);
  EXPECT_LT(g.longest_still_s, 1.0);
  EXPECT_TRUE((g.peak.array() > 0.02 * r.array()).all()) << g.peak.transpose();
  // Screwdriving: Mz pulses of 25–75 % of rated, dropped within 5 ms.
  const LoadProfile screw = MakeWorkCycle("screwdriving", r, 2, 0.0);
  const Extent s = Scan(screw, r, 0.0, 300.0);
  EXPECT_GE(s.peak(5), 0.25 * r(5));
  EXPECT_LE(s.peak(5), 0.75 * r(5));
  EXPECT_LT(s.peak(0), 1e-9);
  // Night idle: no load, 18–26 °C cycles with the ripple.
  const LoadProfile night = MakeWorkCycle("night-idle", r, 2, 0.0);
  const Extent n = Scan(night, r, 0.0, 86400.0 - 1.0, 1.0);
  EXPECT_EQ(n.peak.norm(), 0.0);
  EXPECT_LT(n.t_min, 18.6);
  EXPECT_GT(n.t_max, 25.4);
  // Palletising: holds of ≥ 2 s under 25–60 % of rated Fz.
  const LoadProfile pal = MakeWorkCycle("palletising", r, 2, 0.0);
  const Extent p = Scan(pal, r, 0.0, 300.0);
  EXPECT_GE(p.longest_still_s, 2.0);
  EXPECT_GE(p.peak(2), 0.25 * r(2));
  // Polishing: the spindle's vibration — the load's spectrum at one frequency of 110–190 Hz
  // (a 1 s DFT scan at 0.25 Hz steps), in contact ≥ 1 % of rated on Fz.
  const LoadProfile pol = MakeWorkCycle("polishing", r, 2, 0.0);
  double best_hz = 0.0;
  double best = 0.0;
  for (double f = 100.0; f <= 200.0; f += 0.25) {
    double re = 0.0;
    double im = 0.0;
    for (int i = 0; i < 1000; ++i) {
      const double t = 5.0 + i * 1e-3;
      re += pol.LoadAt(t)(2) * std::cos(2 * std::numbers::pi * f * t);
      im += pol.LoadAt(t)(2) * std::sin(2 * std::numbers::pi * f * t);
    }
    const double a = 2.0 * std::hypot(re, im) / 1000.0;
    if (a > best) {
      best = a;
      best_hz = f;
    }
  }
  EXPECT_GE(best_hz, 110.0);
  EXPECT_LE(best_hz, 190.0);
  EXPECT_GT(best, 0.8 * 0.01 * r(2));
}

}  // namespace
}  // namespace ftstack::sim
