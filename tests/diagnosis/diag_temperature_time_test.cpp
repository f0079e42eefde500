// A sensor whose span falls with temperature, loaded at several temperatures (each visited once),
// from a generator written for this test only: where the temperature is monotone in time a drift
// in time and the recorded temperature explain the same data, and no drift in time may be claimed
// as identified; where it is not, the thermal effect is named with its coefficient.
// Development seed 1 and validation seed 11 were fixed before the method changed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "diagnosis/engine/diagnose.hpp"
#include "tests/diagnosis/random_sensor.hpp"

namespace ftstack::diag {
namespace {

constexpr double kSpanPerK = -0.015;  ///< relative span change per kelvin
constexpr double kRefC = 20.0;

/// 4 bridges at 50 Hz: at each temperature of `levels_c` (°C, in that order) ten random loads
/// held 3 s each; between levels 10 s unloaded while the temperature moves to the next level along
/// a smooth step (half a cosine). The real span is S·(1 + kSpanPerK·(T − 20 °C)); the sim has no
/// temperature effect. Noise σ = 1e-3 mV/V.
DiagData SpanOverTemperature(const std::vector<double>& levels_c, unsigned seed) {
  testing::RandomSensor rig(seed, 4);
  const double dt = 0.02;
  const double hold_s = 3.0;
  const double move_s = 10.0;
  const double level_s = 10 * hold_s + move_s;
  const double duration = level_s * static_cast<double>(levels_c.size());
  std::vector<Eigen::VectorXd> loads;
  for (std::size_t k = 0; k < 10 * levels_c.size(); ++k) {
    Eigen::VectorXd w(6);
    for (int a = 0; a < 6; ++a) w(a) = 40.0 * rig.U();
    loads.push_back(w);
  }
  DiagData d;
  d.sim_name = "independent generator";
  d.real_name = "span over temperature";
  const auto n = static_cast<Eigen::Index>(duration / dt);
  d.sim_mvv.resize(n, 4);
  d.real_mvv.resize(n, 4);
  d.wrench.resize(n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    const auto level = std::min(static_cast<std::size_t>(t / level_s), levels_c.size() - 1);
    const double in_level = t - static_cast<double>(level) * level_s;
    double temp = levels_c[level];
    Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
    if (in_level < 10 * hold_s) {
      w = loads[10 * level + static_cast<std::size_t>(in_level / hold_s)];
    } else if (level + 1 < levels_c.size()) {
      const double x = (in_level - 10 * hold_s) / move_s;
      temp += (levels_c[level + 1] - temp) * 0.5 * (1.0 - std::cos(M_PI * x));
    }
    d.t_s.push_back(t);
    d.temp_c.push_back(temp);
    d.wrench.row(i) = w.transpose().cast<float>();
    const Eigen::VectorXd b = rig.s * w;
    for (int c = 0; c < 4; ++c) {
      d.sim_mvv(i, c) = b(c);
      d.real_mvv(i, c) = b(c) * (1.0 + kSpanPerK * (temp - kRefC)) + 1e-3 * rig.g(rig.rng);
    }
  }
  return d;
}

/// No claimed drift in time (a time-based effect not driven by the temperature) is identified; a
/// claimed, identified thermal span effect has the true coefficient within 5 %. Returns whether
/// the thermal span effect was named and identified.
bool CheckNoTimeStory(const Report& r, const char* what, unsigned seed) {
  bool thermal = false;
  for (const ClaimedEffect& e : r.effects) {
    const bool time_based = HasTrait(e.fit, kTimeBased) && !HasTrait(e.fit, kNeedsTemperature);
    std::printf("%s seed %u: %s %s%s; %s\n", what, seed, e.fit.name.c_str(),
                e.confounded_with.empty() ? "identified" : "confounded with ",
                e.confounded_with.empty() ? "" : e.confounded_with.front().c_str(),
                e.fit.params.dump().substr(0, 160).c_str());
    if (time_based) {
      EXPECT_FALSE(e.confounded_with.empty())
          << what << " seed " << seed << ": " << e.fit.name << " claimed as identified";
    }
    if (e.fit.name == "thermal_span_drift" && e.confounded_with.empty()) {
      thermal = true;
      EXPECT_NEAR(e.fit.params["coef_per_K"].get<double>(), kSpanPerK, 0.05 * std::fabs(kSpanPerK))
          << e.fit.params.dump();
    }
  }
  return thermal;
}

class TemperatureTime : public ::testing::TestWithParam<unsigned> {};

TEST_P(TemperatureTime, MonotoneTemperatureIsNotClaimedAsADriftInTime) {
  const DiagData data = SpanOverTemperature({20.0, 21.0, 22.0, 23.0, 24.0}, GetParam());
  const Report r = Diagnose(data);
  ASSERT_FALSE(r.effects.empty());
  CheckNoTimeStory(r, "monotone", GetParam());
  EXPECT_NE(r.verdict, "excitation_drift");
  EXPECT_NE(r.verdict, "zero_drift");
}

TEST_P(TemperatureTime, TemperatureNotMonotoneInTimeIsNamedWithItsCoefficient) {
  const DiagData data = SpanOverTemperature({21.0, 24.0, 20.0, 23.0, 22.0}, GetParam());
  const Report r = Diagnose(data);
  ASSERT_FALSE(r.effects.empty());
  EXPECT_TRUE(CheckNoTimeStory(r, "not monotone", GetParam()));
  EXPECT_EQ(r.verdict, "thermal_span_drift");
}

INSTANTIATE_TEST_SUITE_P(Development, TemperatureTime, ::testing::Values(1u));
INSTANTIATE_TEST_SUITE_P(Validation, TemperatureTime, ::testing::Values(11u));

}  // namespace
}  // namespace ftstack::diag
