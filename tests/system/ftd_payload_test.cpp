// Gravity compensation end to end: ftd --payload with a simulated payload in eight orientations;
// a libmodbus client writes the gravity vector and switches compensation on; the wrench reads zero
// within the noise-derived tolerance.
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

#include "calibration/file/payload_file.hpp"
#include "firmware/register_map.hpp"
#include "tests/calibration/run_ftcal.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/sim_noise.hpp"

namespace ftstack {
namespace {

using Eigen::Vector3d;

std::vector<std::uint16_t> Floats(const Vector3d& v) {
  std::vector<std::uint16_t> r(6);
  for (int i = 0; i < 3; ++i) fw::PackFloat32(static_cast<float>(v(i)), &r[2 * i]);
  return r;
}

/// Reads the input image once `n` more samples have been published (up to 10 s).
bool ReadAfter(modbus_t* ctx, std::uint32_t n, std::array<std::uint16_t, 85>* r) {
  std::uint16_t seq[2] = {0, 0};
  if (modbus_read_input_registers(ctx, fw::kInSequence, 2, seq) != 2) return false;
  const std::uint32_t start = fw::UnpackU32(seq);
  for (int i = 0; i < 1000; ++i) {
    if (modbus_read_input_registers(ctx, 0, 85, r->data()) != 85) return false;
    if (fw::UnpackU32(&(*r)[fw::kInSequence]) - start >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

TEST(FtdPayload, EightOrientationsReadZeroAfterTheGravityVectorIsWritten) {
  test::TempDir dir("ftd_payload");
  const double mass = 2.2;
  const Vector3d com(0.015, -0.010, 0.060), fb(0.6, -0.4, 1.1), mb(0.02, -0.015, 0.01);
  cal::PayloadFile pf;
  pf.date = "2026-11-25";
  pf.mass_kg = mass;
  pf.com_m = {com.x(), com.y(), com.z()};
  pf.force_bias_n = {fb.x(), fb.y(), fb.z()};
  pf.moment_bias_nm = {mb.x(), mb.y(), mb.z()};
  cal::SavePayloadFile(dir / "payload.json", pf);
  const std::uint32_t file_crc = cal::LoadPayloadFile(dir / "payload.json").crc32;

  const test::SimNoise noise = test::DeriveSimNoise();
  const std::array<double, 6>& sigma = noise.sigma;
  const std::array<double, 6>& fixed_error = noise.fixed_error;
  constexpr int kFilter = 256;
  const double d = M_PI / 180.0;
  const std::array<std::array<double, 3>, 8> rpy = {{{0, 0, 0},
                                                     {180, 0, 0},
                                                     {90, 0, 0},
                                                     {-90, 0, 30},
                                                     {0, 90, 0},
                                                     {0, -90, 45},
                                                     {45, 45, 0},
                                                     {-60, 30, 120}}};
  for (const auto& a : rpy) {
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(a[2] * d, Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(a[1] * d, Vector3d::UnitY()) *
                               Eigen::AngleAxisd(a[0] * d, Vector3d::UnitX()))
                                  .toRotationMatrix();
    // The load the sensor carries, worked out in the world frame (weight at the centre of mass).
    const Vector3d weight(0, 0, -mass * 9.80665);
    const Vector3d f = r.transpose() * weight + fb;
    const Vector3d m = r.transpose() * (r * com).cross(weight) + mb;
    const Vector3d g = r.transpose() * Vector3d(0, 0, -9.80665);
    char wrench[256];
    std::snprintf(wrench, sizeof wrench, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", f.x(), f.y(), f.z(),
                  m.x(), m.y(), m.z());
    test::FtdProcess ftd({"--adc", "sim", "--sim-wrench", wrench, "--payload", dir / "payload.json",
                          "--modbus-tcp", "127.0.0.1:0"});
    ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
    modbus_t* ctx = modbus_new_tcp("127.0.0.1", ftd.port());
    modbus_set_response_timeout(ctx, 1, 0);
    ASSERT_EQ(modbus_connect(ctx), 0);
    ASSERT_EQ(modbus_write_register(ctx, fw::kHoldFilterLength, kFilter), 1);
    std::array<std::uint16_t, 85> in{};
    ASSERT_TRUE(ReadAfter(ctx, kFilter + 10, &in));
    EXPECT_EQ(in[fw::kInStatus] & fw::kStatusPayloadComp, 0);
    EXPECT_NEAR(fw::UnpackFloat32(&in[fw::kInWrenchFloat + 4]), f.z(), 0.05);  // uncompensated
    EXPECT_FLOAT_EQ(fw::UnpackFloat32(&in[fw::kInPayloadMass]), static_cast<float>(mass));
    EXPECT_EQ(fw::UnpackU32(&in[fw::kInPayloadCrc]), file_crc);

    const auto regs = Floats(g);
    ASSERT_EQ(modbus_write_registers(ctx, fw::kHoldGravity, 6, regs.data()), 6);
    ASSERT_EQ(modbus_write_register(ctx, fw::kHoldGravityComp, 1), 1);
    ASSERT_TRUE(ReadAfter(ctx, kFilter + 10, &in));
    EXPECT_NE(in[fw::kInStatus] & fw::kStatusPayloadComp, 0);
    for (std::size_t k = 0; k < 6; ++k) {
      // 5σ of the filtered noise + the core's worst case + the compensation's rounding (1 LSB
      // and the gravity's float32 → µm/s² quantisation: |m·c| · 1e-6 N·m, m · 1e-6 N).
      const double tol = 5.0 * sigma[k] / std::sqrt(kFilter) + fixed_error[k] + fw::AxisLsb(k) +
                         mass * 1e-6 + std::fabs(f(static_cast<int>(k % 3))) * 1e-7;
      EXPECT_NEAR(fw::UnpackFloat32(&in[fw::kInWrenchFloat + 2 * k]), 0.0, tol)
          << "axis " << k << " orientation " << a[0] << "," << a[1] << "," << a[2];
    }
    modbus_close(ctx);
    modbus_free(ctx);
    EXPECT_EQ(ftd.Stop(SIGTERM), 0);
  }
}

Eigen::Matrix3d Rpy(double r, double p, double y) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(y * d, Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p * d, Vector3d::UnitY()) * Eigen::AngleAxisd(r * d, Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Runs ftd with the payload's load in orientation r (plus `extra` arguments, and the gravity
/// vector written when `compensate`), filter 256, and returns the wrench it then reads (N, N·m).
std::array<double, 6> FtdReading(double mass, const Vector3d& com, const Eigen::Matrix3d& r,
                                 std::vector<std::string> extra, bool compensate) {
  const Vector3d weight(0, 0, -mass * 9.80665);
  const Vector3d f = r.transpose() * weight;
  const Vector3d m = r.transpose() * (r * com).cross(weight);
  char wrench[256];
  std::snprintf(wrench, sizeof wrench, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", f.x(), f.y(), f.z(), m.x(),
                m.y(), m.z());
  std::vector<std::string> args = {"--adc", "sim",          "--sim-wrench",
                                   wrench,  "--modbus-tcp", "127.0.0.1:0"};
  args.insert(args.end(), extra.begin(), extra.end());
  test::FtdProcess ftd(args);
  std::array<double, 6> out{};
  out.fill(NAN);
  if (ftd.port() <= 0) return out;
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", ftd.port());
  modbus_set_response_timeout(ctx, 1, 0);
  std::array<std::uint16_t, 85> in{};
  bool ok = modbus_connect(ctx) == 0 && modbus_write_register(ctx, fw::kHoldFilterLength, 256) == 1;
  if (ok && compensate) {
    const auto regs = Floats(r.transpose() * Vector3d(0, 0, -9.80665));
    ok = modbus_write_registers(ctx, fw::kHoldGravity, 6, regs.data()) == 6 &&
         modbus_write_register(ctx, fw::kHoldGravityComp, 1) == 1;
  }
  if (ok && ReadAfter(ctx, 266, &in)) {
    for (std::size_t k = 0; k < 6; ++k) out[k] = fw::UnpackFloat32(&in[fw::kInWrenchFloat + 2 * k]);
  }
  modbus_close(ctx);
  modbus_free(ctx);
  (void)ftd.Stop(SIGTERM);
  return out;
}

/// The robot workflow through the real chain: static readings from ftd in six poses → ftcal
/// payload → ftd --payload reads zero in a seventh pose it was not fitted on.
TEST(FtdPayload, IdentifiedFromFtdReadingsThenCompensatedInANewPose) {
  test::TempDir dir("ftd_payload_flow");
  const double mass = 1.4;
  const Vector3d com(0.010, 0.020, 0.070);
  const std::vector<Eigen::Matrix3d> poses = {Rpy(0, 0, 0),   Rpy(180, 0, 0), Rpy(90, 0, 0),
                                              Rpy(-90, 0, 0), Rpy(0, 90, 0),  Rpy(0, -90, 0)};
  {
    std::ofstream csv(dir / "poses.csv");
    csv << "gx_mps2,gy_mps2,gz_mps2,Fx,Fy,Fz,Mx,My,Mz\n";
    csv.precision(10);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const Eigen::Matrix3d& r = poses[i];
      const Vector3d g = r.transpose() * Vector3d(0, 0, -9.80665);
      // A seed per pose: independent noise (one seed would repeat one noise sequence, which the
      // fit would take for a bias).
      const auto w = FtdReading(mass, com, r, {"--seed", std::to_string(11 + i)}, false);
      csv << g.x() << ',' << g.y() << ',' << g.z();
      for (double v : w) csv << ',' << v;
      csv << '\n';
    }
  }
  std::string out;
  ASSERT_EQ(
      test::RunFtcal("payload --in " + (dir / "poses.csv") + " --out " + (dir / "p.json"), &out), 0)
      << out;
  const cal::PayloadFile p = cal::LoadPayloadFile(dir / "p.json");
  EXPECT_NEAR(p.mass_kg, mass, 0.01 * mass) << out;
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(p.com_m[static_cast<std::size_t>(k)], com(k), 1e-3) << out;
  // A pose the fit did not see.
  const auto w = FtdReading(mass, com, Rpy(-50, 35, 100), {"--payload", dir / "p.json"}, true);
  const test::SimNoise noise = test::DeriveSimNoise();
  for (std::size_t k = 0; k < 6; ++k) {
    // Filtered noise + core error + LSB, plus 3σ of what the identification could not pin down
    // (mass and bias for forces; centre of mass and bias for moments), each on the full weight.
    const double id =
        k < 3 ? 3 * (p.mass_sigma_kg * 9.80665 + p.force_bias_sigma_n[k])
              : 3 * (p.com_sigma_m[0] + p.com_sigma_m[1] + p.com_sigma_m[2]) * mass * 9.80665 +
                    3 * p.moment_bias_sigma_nm[k - 3];
    const double tol = 5.0 * noise.sigma[k] / 16.0 + noise.fixed_error[k] + fw::AxisLsb(k) + id;
    EXPECT_NEAR(w[k], 0.0, tol) << "axis " << k << "\n" << out;
  }
}

TEST(FtdPayload, ACorruptPayloadFileStopsFtdWithOneLine) {
  test::TempDir dir("ftd_payload_bad");
  std::ofstream(dir / "p.json") << "{\"schema\": \"ftstack-payload/1\", \"mass_kg\": 1,";
  test::FtdProcess ftd({"--adc", "sim", "--payload", dir / "p.json", "--modbus-tcp", "127.0.0.1:0"},
                       false);
  EXPECT_NE(ftd.Wait(10.0), 0);
  EXPECT_NE(ftd.Stderr().find("--payload refused"), std::string::npos) << ftd.Stderr();
  EXPECT_NE(ftd.Stderr().find("p.json:1:"), std::string::npos) << ftd.Stderr();
}

}  // namespace
}  // namespace ftstack
