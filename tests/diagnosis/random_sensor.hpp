// A random linear sensor for the diagnosis tests' own generators: the sensitivity and the random
// draws that follow it, from one seed.
#pragma once

#include <Eigen/Dense>
#include <random>

namespace ftstack::diag::testing {

/// bridges × 6 sensitivity with entries uniform within ±0.02 (mV/V per N or N·m), drawn first
/// from `rng`; the generator then draws its own values from u (uniform ±1) and g (unit normal).
struct RandomSensor {
  RandomSensor(unsigned seed, int bridges) : rng(seed), s(bridges, 6) {
    for (int c = 0; c < bridges; ++c) {
      for (int a = 0; a < 6; ++a) s(c, a) = 0.02 * u(rng);
    }
  }
  double U() { return u(rng); }
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  std::normal_distribution<double> g{0.0, 1.0};
  Eigen::MatrixXd s;
};

}  // namespace ftstack::diag::testing
