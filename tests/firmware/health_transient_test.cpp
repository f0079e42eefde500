// The watch against load changes too small or too fast for the load-change gate: a contact
// bounce (a decaying oscillation whose 0.1 s mean stays under the gate) is broadband and fills one
// block's 50/60 Hz bins and noise, where a steady tone or noise rise fills every block; a load
// that sways during a hold is not a still hold, and its slow approach is not judged as creep; a
// steady tone's crossings after a step are not the mount's ringing.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/firmware/health_scene.hpp"

namespace ftstack::fw {
namespace {

/// A bounce on Fz every 4.3 s from 6 s on: 10 % of rated, 33 Hz, decaying with τ = 20 ms
/// (zero mean over the bounce within 0.3 % of rated: below the 1 % load-change gate), plus a
/// 50 Hz tone of `tone` × rated on Fz from the start.
Scene Bounces(double tone) {
  Scene s;
  s.load = [tone](double t, std::array<double, 6>& y, double&) {
    y[2] = tone * kRated[2] * std::sin(2 * M_PI * 50.0 * t + 0.3);
    if (t < 6.0) return;
    const double since = std::fmod(t - 6.0, 4.3);
    y[2] += 0.1 * kRated[2] * std::exp(-since / 0.02) * std::sin(2 * M_PI * 33.0 * since);
  };
  return s;
}

TEST(HealthTransient, ContactBouncesAreNoToneAndNoNoiseRise) {
  Runner run(Bounces(0.0));
  bool any = false;
  run.Run(60, [&](double) { any = any || run.report().findings != 0; });
  EXPECT_FALSE(any) << "findings 0x" << std::hex << run.report().findings;
}

TEST(HealthTransient, ATonePersistsThroughTheBounces) {
  Runner run(Bounces(0.001));
  run.Run(60);
  ASSERT_TRUE(Has(run.report(), HealthCause::kMains50));
  const HealthFinding* fd = Slot(run.report(), HealthCause::kMains50);
  ASSERT_NE(fd, nullptr);
  EXPECT_NEAR(fd->error_lsb[2], 0.001 * kRated[2], 0.05 * 0.001 * kRated[2]);
  EXPECT_FALSE(Has(run.report(), HealthCause::kMains60));
  EXPECT_FALSE(Has(run.report(), HealthCause::kNoiseFloor));
}

/// Fz steps between 0 and 15 % of rated every 10 s; after each step an approach of 0.3 % of rated
/// in the step's direction (τ 4 s: creep-like); with `sway`, a 1 Hz sway of 1 % of rated all the
/// time (whole periods in the 2 s segments, so their means see only the approach; 0.63 % of rated
/// per 0.1 s at most: under the 1 % gate).
Scene SwayingHolds(bool sway) {
  Scene s;
  s.load = [sway](double t, std::array<double, 6>& y, double&) {
    const int k = static_cast<int>(t / 10.0);
    const double since = t - 10.0 * k;
    const double dir = k % 2 == 0 ? -1.0 : 1.0;  // odd periods step up to 15 %, even back down
    y[2] = (k % 2 == 1 ? 0.15 : 0.0) * kRated[2];
    if (k > 0) y[2] += dir * 0.003 * kRated[2] * (1.0 - std::exp(-since / 4.0));
    if (sway) y[2] += 0.01 * kRated[2] * std::sin(2 * M_PI * 1.0 * t);
  };
  return s;
}

TEST(HealthTransient, AnApproachInStillHoldsIsCreep) {
  Runner run(SwayingHolds(false));
  run.Run(60);
  EXPECT_TRUE(Has(run.report(), HealthCause::kCreep));
}

TEST(HealthTransient, TheSameApproachUnderASwayIsNotJudged) {
  Runner run(SwayingHolds(true));
  bool creep = false;
  run.Run(120, [&](double) { creep = creep || Has(run.report(), HealthCause::kCreep); });
  EXPECT_FALSE(creep);
}

/// Fz steps through 0, 40, 0 and 10 % of rated every 7.77 s (the tone's phase differs at every
/// step), each followed by a ringing of `ring_hz` (1 % of the step, ζ = 0.04) and, in its first
/// second, a slow drift of 0, 1 or 2 × `drift` of rated per s (the load still moving under the
/// gate, as a re-orienting arm), under a steady 50 Hz tone of `tone` × rated on every axis.
Scene RingingStepsUnderATone(double ring_hz, double tone, double drift) {
  Scene s;
  s.load = [=](double t, std::array<double, 6>& y, double&) {
    const int k = static_cast<int>(t / 7.77);
    const double since = t - k * 7.77;
    const double levels[4] = {0.0, 0.4, 0.0, 0.1};
    const double step = (levels[k % 4] - levels[(k + 3) % 4]) * kRated[2];
    const double wn = 2 * M_PI * ring_hz, zeta = 0.04;
    for (std::size_t r = 0; r < 6; ++r) {
      y[r] = tone * kRated[r] * std::sin(2 * M_PI * 50.0 * t + 0.7 * static_cast<double>(r));
    }
    const double moved = drift * (k % 3) * (k % 2 == 1 ? 1.0 : -1.0);
    y[2] += levels[k % 4] * kRated[2] + moved * kRated[2] * std::min(since, 1.0) +
            (k == 0 ? 0.0 : 0.01 * step * std::exp(-zeta * wn * since) * std::cos(wn * since));
  };
  return s;
}

/// An assembly cell's contacts every 5.3 s: a part of 2 % of rated hangs on Fz; the contact rises
/// to 5–15 % of rated in 5 ms and bounces (halving every 15 ms, straight lines between the turns),
/// then the insertion force ramps to 15 % over 0.7 s while the chamfer pushes Fx and Fy to a new
/// random value of ±2 % of rated every 70 ms; held 0.3 s, released in 50 ms. No structure rings:
/// every swing after the edge is the load's own.
Scene AssemblyContacts(double insert = 0.15, double ins_s = 0.7) {
  Scene s;
  s.load = [=](double t, std::array<double, 6>& y, double&) {
    const int k = static_cast<int>(t / 5.3);
    const double since = t - 5.3 * k - 1.0;
    y[2] = -0.02 * kRated[2];
    if (k == 0 || since < 0.0) return;
    // Deterministic pseudo-random values per cycle and key, uniform in [−1, 1].
    const auto rnd = [k](int i) {
      std::uint64_t z =
          static_cast<std::uint64_t>(k) * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) / 4503599627370496.0 - 1.0;
    };
    const double contact = (0.1 + 0.05 * rnd(0)) * kRated[2];
    const double bounce_end = 0.005 + 5 * 0.015;
    double fz = 0.0;
    if (since < 0.005) {
      fz = contact * since / 0.005;
    } else if (since < bounce_end) {
      const int i = static_cast<int>((since - 0.005) / 0.015);
      const double u = (since - 0.005 - 0.015 * i) / 0.015;
      fz = contact * (std::pow(-0.5, i) * (1 - u) + std::pow(-0.5, i + 1) * u);
    } else if (since < bounce_end + 1.0) {
      const double ins = std::min((since - bounce_end) / ins_s, 1.0);
      const double last = contact * std::pow(-0.5, 5);
      fz = last + (insert * kRated[2] - last) * ins;
      const int j = static_cast<int>((since - bounce_end) / 0.07);
      const double u = (since - bounce_end - 0.07 * j) / 0.07;
      for (std::size_t r = 0; r < 2; ++r) {
        const double a = j == 0 ? 0.0 : rnd(2 * j + static_cast<int>(r));
        const double b = rnd(2 * j + 2 + static_cast<int>(r));
        y[r] = 0.02 * kRated[r] * (a * (1 - u) + b * u);
      }
    } else if (since < bounce_end + 1.05) {
      fz = insert * kRated[2] * (1 - (since - bounce_end - 1.0) / 0.05);
    }
    y[2] += fz;
  };
  return s;
}

TEST(HealthTransient, ALoadThatBouncesAndMovesAfterItsStepIsNoRingingOfTheMount) {
  Runner run(AssemblyContacts(0.1, 0.7));
  bool mount = false;
  run.Run(600, [&](double) { mount = mount || Has(run.report(), HealthCause::kResonanceShift); });
  EXPECT_FALSE(mount) << "ringing read at " << run.report().ring_mhz << " mHz";
}

TEST(HealthTransient, ALargeToneIsNoRingingOfTheMount) {
  // 0.5 % of rated: larger than the largest step's ringing (0.4 %), which the drifts after the
  // steps bias differently; the mount has not changed.
  Runner run(RingingStepsUnderATone(25.0, 0.005, 0.02));
  bool mount = false;
  run.Run(120, [&](double) { mount = mount || Has(run.report(), HealthCause::kResonanceShift); });
  EXPECT_FALSE(mount) << "ringing read at " << run.report().ring_mhz << " mHz";
  EXPECT_TRUE(Has(run.report(), HealthCause::kMains50));
}

TEST(HealthTransient, AMountShiftIsStillSeenUnderASmallTone) {
  // A tone at the mains limit (0.05 % of rated: an eighth of the large step's ringing);
  // commissioned at 25 Hz, the mount now rings 10 % higher. The tone moves the dated crossings:
  // read within 4 % (without the tone within 1.5 %), the 10 % shift stays clear of the 5 % limit.
  HealthThresholds th;
  th.ring_ref_dhz = 250;
  Runner run(RingingStepsUnderATone(27.5, 0.0005, 0.0), th);
  run.Run(60);
  EXPECT_TRUE(Has(run.report(), HealthCause::kResonanceShift));
  EXPECT_NEAR(run.report().ring_mhz, 27500, 0.04 * 27500);
}

}  // namespace
}  // namespace ftstack::fw
