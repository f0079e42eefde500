// Payload identification: accuracy on simulated robot poses with the built-in sensor's noise, a
// closed-form reference, honest uncertainties, refusal of degenerate pose sets, the payload file.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "calibration/fit/payload.hpp"
#include "sim/default_sensor.hpp"
#include "tests/calibration/run_ftcal.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

using Eigen::Vector3d;
using ftstack::cal::FitPayload;
using ftstack::cal::PayloadIdentError;
using ftstack::cal::PayloadReading;

constexpr double kG = 9.80665;

/// Single-sample noise of the built-in sensor per axis: fraction of rated (docs/physics.md,
/// "noise per axis", checked by DefaultSensor.MeetsItsDesignBrief) × rated range.
std::array<double, 6> SensorNoise() {
  const std::array<double, 6> fraction = {1.15e-4, 1.15e-4, 1.01e-4, 0.97e-4, 0.97e-4, 1.24e-4};
  const ftstack::Wrench rated = ftstack::sim::DefaultRated();
  std::array<double, 6> s{};
  for (int a = 0; a < 6; ++a) s[static_cast<std::size_t>(a)] = fraction[a] * rated(a);
  return s;
}

struct Truth {
  double mass_kg = 1.85;
  Vector3d com_m{0.012, -0.007, 0.064};
  Vector3d force_bias_n{0.8, -0.45, 1.3};
  Vector3d moment_bias_nm{0.031, -0.022, 0.009};
};

/// Independent generator: the robot holds the sensor with orientation R (sensor axes in the
/// world); the payload's weight acts at its centre of mass, both worked out in the world frame
/// and only then expressed in the sensor frame.
PayloadReading Simulate(const Truth& t, const Eigen::Matrix3d& r, std::mt19937* rng, bool noisy) {
  const Vector3d weight_world(0, 0, -t.mass_kg * kG);
  const Vector3d com_world = r * t.com_m;
  const Vector3d moment_world = com_world.cross(weight_world);
  const Vector3d f = r.transpose() * weight_world + t.force_bias_n;
  const Vector3d m = r.transpose() * moment_world + t.moment_bias_nm;
  const std::array<double, 6> sigma = SensorNoise();
  std::normal_distribution<double> n01(0.0, 1.0);
  PayloadReading out;
  const Vector3d g = r.transpose() * Vector3d(0, 0, -kG);
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    out.gravity_mps2[i] = g(k);
    out.wrench[i] = f(k) + (noisy ? sigma[i] * n01(*rng) : 0.0);
    out.wrench[3 + i] = m(k) + (noisy ? sigma[3 + i] * n01(*rng) : 0.0);
  }
  return out;
}

/// A generator for noiseless readings (never drawn from).
std::mt19937& Quiet() {
  static std::mt19937 r(1);
  return r;
}

Eigen::Matrix3d Rpy(double roll_deg, double pitch_deg, double yaw_deg) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(yaw_deg * d, Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * d, Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * d, Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Eight wrist orientations a robot reaches easily.
std::vector<Eigen::Matrix3d> EightPoses() {
  return {Rpy(0, 0, 0),  Rpy(180, 0, 0),  Rpy(90, 0, 0),  Rpy(-90, 0, 30),
          Rpy(0, 90, 0), Rpy(0, -90, 45), Rpy(45, 45, 0), Rpy(-60, 30, 120)};
}

TEST(Payload, EightPosesWithSensorNoiseMeetTheAcceptance) {
  std::mt19937 rng(7);
  const Truth t;
  const std::array<double, 6> sigma = SensorNoise();
  std::vector<PayloadReading> rs;
  for (const auto& r : EightPoses()) rs.push_back(Simulate(t, r, &rng, true));
  const auto fit = FitPayload(rs);
  const auto& p = fit.file;
  EXPECT_NEAR(p.mass_kg, t.mass_kg, 0.01 * t.mass_kg);
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_NEAR(p.com_m[i], t.com_m(k), 1e-3) << k;
    EXPECT_NEAR(p.force_bias_n[i], t.force_bias_n(k), 2 * sigma[i]) << k;
    EXPECT_NEAR(p.moment_bias_nm[i], t.moment_bias_nm(k), 2 * sigma[3 + i]) << k;
  }
  // The residuals are the noise: RMS within a factor 2 of the per-axis σ.
  EXPECT_GT(p.force_rms_n, 0.5 * sigma[0]);
  EXPECT_LT(p.force_rms_n, 2.0 * sigma[2]);
  EXPECT_LT(p.moment_rms_nm, 2.0 * sigma[5]);
  EXPECT_EQ(p.readings, 8u);
}

TEST(Payload, NoiselessDataIsRecoveredExactly) {
  const Truth t;
  std::vector<PayloadReading> rs;
  for (const auto& r : EightPoses()) rs.push_back(Simulate(t, r, &Quiet(), false));
  const auto p = FitPayload(rs).file;
  EXPECT_NEAR(p.mass_kg, t.mass_kg, 1e-9);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(p.com_m[static_cast<std::size_t>(k)], t.com_m(k), 1e-10);
    EXPECT_NEAR(p.moment_bias_nm[static_cast<std::size_t>(k)], t.moment_bias_nm(k), 1e-10);
  }
}

/// Gravity along ±x, ±y, ±z: Σg = 0 decouples the least squares, whose solution is then
/// m = Σ g·F / (6|g|²), F_b = mean F, M_b = mean M, m·c = Σ g × M / (4|g|²).
TEST(Payload, MatchesTheClosedFormOfTheSixAxisPoseSet) {
  std::mt19937 rng(11);
  const Truth t;
  const std::vector<Eigen::Matrix3d> poses = {Rpy(0, 0, 0),   Rpy(180, 0, 0), Rpy(90, 0, 0),
                                              Rpy(-90, 0, 0), Rpy(0, 90, 0),  Rpy(0, -90, 0)};
  std::vector<PayloadReading> rs;
  for (const auto& r : poses) rs.push_back(Simulate(t, r, &rng, true));
  Vector3d sum_f = Vector3d::Zero(), sum_m = Vector3d::Zero(), sum_gxm = Vector3d::Zero();
  double sum_gf = 0;
  for (const auto& r : rs) {
    const Vector3d g(r.gravity_mps2[0], r.gravity_mps2[1], r.gravity_mps2[2]);
    const Vector3d f(r.wrench[0], r.wrench[1], r.wrench[2]);
    const Vector3d m(r.wrench[3], r.wrench[4], r.wrench[5]);
    sum_f += f;
    sum_m += m;
    sum_gf += g.dot(f);
    sum_gxm += g.cross(m);
  }
  const double mass = sum_gf / (6 * kG * kG);
  const Vector3d com = sum_gxm / (4 * kG * kG) / mass;
  const auto p = FitPayload(rs).file;
  EXPECT_NEAR(p.mass_kg, mass, 1e-9);
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_NEAR(p.force_bias_n[i], sum_f(k) / 6, 1e-9);
    EXPECT_NEAR(p.moment_bias_nm[i], sum_m(k) / 6, 1e-11);
    EXPECT_NEAR(p.com_m[i], com(k), 1e-11);
  }
}

/// The reported σ (from the residuals) against the spread over repeated noisy identifications.
TEST(Payload, ReportedUncertaintyMatchesTheScatterOfRepeatedFits) {
  std::mt19937 rng(3);
  const Truth t;
  const int trials = 400;
  double sum = 0, sum2 = 0, sigma_sum = 0, com_sum = 0, com_sum2 = 0, com_sigma = 0;
  for (int k = 0; k < trials; ++k) {
    std::vector<PayloadReading> rs;
    for (const auto& r : EightPoses()) rs.push_back(Simulate(t, r, &rng, true));
    const auto p = FitPayload(rs).file;
    sum += p.mass_kg;
    sum2 += p.mass_kg * p.mass_kg;
    sigma_sum += p.mass_sigma_kg;
    com_sum += p.com_m[2];
    com_sum2 += p.com_m[2] * p.com_m[2];
    com_sigma += p.com_sigma_m[2];
  }
  const double sd = std::sqrt(sum2 / trials - std::pow(sum / trials, 2));
  const double com_sd = std::sqrt(com_sum2 / trials - std::pow(com_sum / trials, 2));
  // Residual-based σ with 20 and 18 degrees of freedom: its mean is within ~2 % of the true σ;
  // the sample SD of 400 trials is within ~7 % (2 standard errors).
  EXPECT_NEAR(sigma_sum / trials / sd, 1.0, 0.15);
  EXPECT_NEAR(com_sigma / trials / com_sd, 1.0, 0.15);
}

TEST(Payload, RefusesAPoseSetWithOneGravityDirection) {
  const Truth t;
  std::vector<PayloadReading> rs(4, Simulate(t, Rpy(0, 0, 0), &Quiet(), false));
  try {
    (void)FitPayload(rs);
    FAIL() << "accepted";
  } catch (const PayloadIdentError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("mass is not identifiable"), std::string::npos) << w;
    EXPECT_NE(w.find("gravity along the sensor's x axis"), std::string::npos) << w;
  }
}

TEST(Payload, RefusesGravityOnlyAlongZAndNamesTheCentreOfMassAlongZ) {
  // Tool up and tool down (rotations about x by 0 and 180°): gravity ±z in the sensor frame.
  const Truth t;
  std::vector<PayloadReading> rs = {Simulate(t, Rpy(0, 0, 0), &Quiet(), false),
                                    Simulate(t, Rpy(180, 0, 0), &Quiet(), false),
                                    Simulate(t, Rpy(180, 0, 90), &Quiet(), false)};
  try {
    (void)FitPayload(rs);
    FAIL() << "accepted";
  } catch (const PayloadIdentError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("centre of mass along"), std::string::npos) << w;
    EXPECT_NE(w.find("(the sensor's z axis) is not identifiable"), std::string::npos) << w;
    EXPECT_EQ(w.find("mass is not identifiable"), std::string::npos) << w;
  }
}

TEST(Payload, RefusesTooFewAndNonFiniteReadings) {
  const Truth t;
  std::vector<PayloadReading> rs = {Simulate(t, Rpy(0, 0, 0), &Quiet(), false),
                                    Simulate(t, Rpy(90, 0, 0), &Quiet(), false)};
  EXPECT_THROW((void)FitPayload(rs), PayloadIdentError);
  rs.push_back(Simulate(t, Rpy(0, 90, 0), &Quiet(), false));
  EXPECT_NO_THROW((void)FitPayload(rs));
  rs[1].wrench[4] = NAN;
  EXPECT_THROW((void)FitPayload(rs), PayloadIdentError);
}

TEST(PayloadFile, RoundTripsAndRefusesCorruption) {
  ftstack::test::TempDir dir("payload");
  const Truth t;
  std::vector<PayloadReading> rs;
  for (const auto& r : EightPoses()) rs.push_back(Simulate(t, r, &Quiet(), false));
  auto p = FitPayload(rs).file;
  p.date = "2026-11-25";
  ftstack::cal::SavePayloadFile(dir / "p.json", p);
  const auto q = ftstack::cal::LoadPayloadFile(dir / "p.json");
  EXPECT_EQ(q.mass_kg, p.mass_kg);
  EXPECT_EQ(q.com_m, p.com_m);
  EXPECT_EQ(q.date, "2026-11-25");
  std::ifstream in(dir / "p.json");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("\"mass\": \"kg\""), std::string::npos);
  // A changed digit: CRC mismatch.
  const auto pos = text.find("\"mass_kg\": 1.");
  ASSERT_NE(pos, std::string::npos);
  std::string bad = text;
  bad[pos + 13] = bad[pos + 13] == '9' ? '8' : '9';
  std::ofstream(dir / "bad.json") << bad;
  EXPECT_THROW((void)ftstack::cal::LoadPayloadFile(dir / "bad.json"),
               ftstack::cal::PayloadFileError);
  std::ofstream(dir / "trunc.json") << text.substr(0, text.size() / 2);
  try {
    (void)ftstack::cal::LoadPayloadFile(dir / "trunc.json");
    FAIL();
  } catch (const ftstack::cal::PayloadFileError& e) {
    EXPECT_NE(std::string(e.what()).find("trunc.json:"), std::string::npos) << e.what();
  }
}

}  // namespace

namespace {

using ftstack::test::RunFtcal;

void WriteReadings(const std::string& path, const std::vector<PayloadReading>& rs) {
  std::ofstream o(path);
  o << "# source: test_payload\ngx_mps2,gy_mps2,gz_mps2,Fx,Fy,Fz,Mx,My,Mz\n";
  o.precision(12);
  for (const auto& r : rs) {
    o << r.gravity_mps2[0] << ',' << r.gravity_mps2[1] << ',' << r.gravity_mps2[2];
    for (double v : r.wrench) o << ',' << v;
    o << '\n';
  }
}

TEST(FtcalPayload, WritesAVerifiedPayloadFileOrRefusesWithTheReason) {
  ftstack::test::TempDir dir("ftcal_payload");
  std::mt19937 rng(5);
  const Truth t;
  std::vector<PayloadReading> rs;
  for (const auto& r : EightPoses()) rs.push_back(Simulate(t, r, &rng, true));
  WriteReadings(dir / "poses.csv", rs);
  std::string out;
  ASSERT_EQ(RunFtcal("payload --in " + (dir / "poses.csv") + " --out " + (dir / "p.json"), &out), 0)
      << out;
  EXPECT_NE(out.find("mass 1.8"), std::string::npos) << out;
  const auto p = ftstack::cal::LoadPayloadFile(dir / "p.json");
  EXPECT_NEAR(p.mass_kg, t.mass_kg, 0.01 * t.mass_kg);
  EXPECT_EQ(p.date.size(), 10u);

  WriteReadings(dir / "flat.csv", {rs[0], rs[1], rs[0]});  // gravity ±z only
  out.clear();
  EXPECT_EQ(RunFtcal("payload --in " + (dir / "flat.csv") + " --out " + (dir / "q.json"), &out), 1);
  EXPECT_NE(out.find("is not identifiable"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "q.json"));
}

}  // namespace
