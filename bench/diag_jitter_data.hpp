// The synthetic 8-bridge recording pair of the ftdiag clock benchmarks (uniform or jittered).
#pragma once

#include <cmath>
#include <random>

#include "diagnosis/loader/data.hpp"

namespace ftstack::bench {

/// 8 bridges, `rows` rows at a nominal 150 Hz, timestamps uniform or jittered by ±30 % of the
/// period (uniform random); a staircase of random loads seen through a fixed 8 × 6 sensitivity,
/// the real side adds a first-order creep (τ = 20 s, integrated with the actual dt) and noise.
inline diag::DiagData MakeJitterData(int rows, bool jitter) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  diag::DiagData d;
  d.sim_name = "bench";
  d.real_name = jitter ? "jittered" : "uniform";
  d.t_s.resize(static_cast<std::size_t>(rows));
  d.wrench.resize(rows, 6);
  d.sim_mvv.resize(rows, 8);
  d.real_mvv.resize(rows, 8);
  Eigen::MatrixXd s(8, 6);
  for (int c = 0; c < 8; ++c) {
    for (int a = 0; a < 6; ++a) s(c, a) = 0.02 * u(rng);
  }
  Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd creep = Eigen::VectorXd::Zero(8);
  double t = 0.0;
  for (int i = 0; i < rows; ++i) {
    const double dt = (1.0 + (jitter ? 0.3 * u(rng) : 0.0)) / 150.0;
    t += dt;
    d.t_s[static_cast<std::size_t>(i)] = t;
    if (i % 600 == 0) {
      for (int a = 0; a < 6; ++a) w(a) = 50.0 * u(rng);
    }
    const Eigen::VectorXd b = s * w;
    creep += (0.01 * b - creep) * (1.0 - std::exp(-dt / 20.0));
    d.wrench.row(i) = w.transpose().cast<float>();
    d.sim_mvv.row(i) = b.transpose();
    for (int c = 0; c < 8; ++c) d.real_mvv(i, c) = b(c) + creep(c) + 2e-4 * g(rng);
  }
  return d;
}

}  // namespace ftstack::bench
