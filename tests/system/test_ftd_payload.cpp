// Gravity compensation end to end: ftd --payload with a simulated payload in eight orientations;
// a libmodbus client writes the gravity vector and switches compensation on; the wrench reads zero
// within the noise-derived tolerance.
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "calibration/payload_file.hpp"
#include "firmware/register_map.hpp"
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
