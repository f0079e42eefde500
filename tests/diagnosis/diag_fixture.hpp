// Closed-form sim/real pairs for the diagnosis unit tests: a rig profile, a linear sensor, one or
// two effects written from their physics (integrated independently of ftdiag's own models), white
// noise. The generator lives in diag_fixture.cpp, built optimised in every configuration.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "diagnosis/loader/data.hpp"
#include "sim/default_sensor.hpp"

namespace ftstack::diag::testing {

/// Piecewise-linear rig profile: steps, holds, up/down sweeps, combined loads, fast taps.
struct RigProfile {
  std::vector<double> t;
  std::vector<Eigen::Matrix<double, 6, 1>> w;
  /// The wrench at time tq, linear between key points, held beyond the ends.
  Eigen::Matrix<double, 6, 1> At(double tq) const;
  double duration() const { return t.back(); }
};

RigProfile MakeRig(unsigned seed, double hold_s = 6.0);

struct FixtureEffect {
  std::string name;
  double size_sigma = 5.0;  ///< peak size of the effect in noise σ
};

struct Fixture {
  DiagData data;
  double truth = 0.0;  ///< the key parameter's true value (effect dependent)
  int truth_channel = -1;
};

/// The fixtures' body temperature at t, °C: a warm-up with a slow oscillation.
double Temperature(double t);

/// Builds a sim/real pair at 200 Hz with noise σ = 1e-4 mV/V and the named effect(s).
Fixture MakeFixture(const std::vector<FixtureEffect>& effects, unsigned seed,
                    double rate_hz = 200.0, double noise = 1e-4, double hold_s = 6.0);

}  // namespace ftstack::diag::testing
