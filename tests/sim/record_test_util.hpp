// Shared fixtures of the recording tests: an explicit linear test sensor, profile files, residuals.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "sim/record.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim::testing_util {

/// Rated range of the test sensor (N, N·m).
inline Wrench TestRated() {
  Wrench r;
  r << 200.0, 200.0, 400.0, 10.0, 10.0, 8.0;
  return r;
}

/// A fixed, well-conditioned 6 × 6 sensitivity (mV/V per N or N·m): about 0.6 mV/V at rated load
/// on each axis's main bridge with a few per cent of cross-talk. Written out here so the tests do
/// not depend on whichever default sensor the simulator ships.
inline Eigen::MatrixXd TestSensitivity() {
  const double m[6][6] = {
      {0.60, 0.02, 0.01, 0.015, -0.01, 0.00}, {-0.01, 0.60, 0.02, 0.00, 0.01, 0.02},
      {0.02, -0.01, 0.60, 0.01, 0.02, -0.01}, {0.00, 0.02, -0.015, 0.60, 0.01, 0.01},
      {0.01, 0.00, 0.02, -0.02, 0.60, 0.015}, {0.02, 0.01, 0.00, 0.01, -0.01, 0.60}};
  Eigen::MatrixXd s(6, 6);
  const Wrench r = TestRated();
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) s(i, j) = m[i][j] / r(j);
  }
  return s;
}

/// Zero output of the test sensor, mV/V (non-zero so zero and load parts are told apart).
inline Eigen::VectorXd TestZero() {
  Eigen::VectorXd z(6);
  z << 0.012, -0.008, 0.02, 0.0, -0.015, 0.005;
  return z;
}

/// A request on the test sensor: 24-bit ADC, gain 128, reference ratio 0.5, no noise.
inline RecordRequest TestRequest(const std::string& profile, std::vector<std::string> effects = {},
                                 double duration_s = 0.0) {
  RecordRequest r;
  r.sensor.name = "test";
  r.sensor.model = std::make_shared<LinearSensorModel>(TestSensitivity(), TestRated(),
                                                       "test-linear", TestZero());
  r.sensor.adc.resolution_bits = 24;
  r.sensor.adc.reference_ratio = 0.5;
  r.sensor.adc_gain = 128;
  r.noise_mvv = 0.0;
  r.seed = 7;
  r.profile = profile;
  r.duration_s = duration_s;
  r.effects = ParseEffects(effects);
  return r;
}

/// One ADC step of that read-out, mV/V: full scale 1000 · 0.5 / 128 over 2^23 − 1 counts.
inline double Lsb() { return (1000.0 * 0.5 / 128.0) / 8388607.0; }

/// real − sim on bridge `ch`.
inline std::vector<double> Residual(const RecordResult& r, int ch) {
  const std::string name = "b" + std::to_string(ch);
  const auto& a = r.real.Column(name);
  const auto& b = r.sim.Column(name);
  std::vector<double> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] - b[i];
  return out;
}

/// real − sim on every bridge: [channel][row].
inline std::vector<std::vector<double>> Residuals(const RecordResult& r) {
  std::vector<std::vector<double>> out;
  for (std::size_t ch = 0; ch < r.real.BridgeCount(); ++ch)
    out.push_back(Residual(r, static_cast<int>(ch)));
  return out;
}

/// The reference wrench of row i.
inline Wrench WrenchAt(const Recording& rec, std::size_t i) {
  Wrench w;
  for (int k = 0; k < 6; ++k) w(k) = rec.Column(WrenchColumns()[static_cast<std::size_t>(k)])[i];
  return w;
}

/// Writes a JSON keyframe profile (times s, wrenches, optional temperatures) and returns its path.
inline std::string WriteProfile(const std::string& name, const std::vector<double>& t,
                                const std::vector<Wrench>& w, double rate_hz,
                                const std::vector<double>& temp_c = {}) {
  const std::string path = ftstack::test::ProcessTempDir() + "/" + name + ".json";
  std::ofstream out(path);
  out.precision(17);
  out << "{\"schema\": \"ftstack-profile/1\", \"rate_hz\": " << rate_hz << ", \"keyframes\": [";
  for (std::size_t i = 0; i < t.size(); ++i) {
    out << (i ? ",\n" : "\n") << "{\"t_s\": " << t[i] << ", \"wrench\": [";
    for (int k = 0; k < 6; ++k) out << (k ? ", " : "") << w[i](k);
    out << "]";
    if (!temp_c.empty()) out << ", \"temp_C\": " << temp_c[i];
    out << "}";
  }
  out << "]}\n";
  return path;
}

/// A wrench with one non-zero component.
inline Wrench Along(int k, double v) {
  Wrench w = Wrench::Zero();
  w(k) = v;
  return w;
}

}  // namespace ftstack::sim::testing_util
