// The interference and noise watch against transients the load-change gate lets through: a
// contact bounce (a decaying oscillation whose 0.1 s mean stays under the gate) is broadband and
// fills one block's 50/60 Hz bins and noise; a steady tone or noise rise fills every block.
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

}  // namespace
}  // namespace ftstack::fw
