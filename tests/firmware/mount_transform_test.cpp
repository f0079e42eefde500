// Mount transform (holding 30–41): a sensor under a robot base reports the wrench in the base
// frame; checked against point forces moved by rigid-body geometry (Eigen, double precision).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "firmware/register_map.hpp"
#include "firmware/tool_transform.hpp"
#include "tests/firmware/register_map_fixture.hpp"

namespace ftstack::fw {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

Eigen::Matrix3d Rot(const ToolTransformParams& p) {
  return (Eigen::AngleAxisd(p.r_deg[2] * kDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p.r_deg[1] * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(p.r_deg[0] * kDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d D(const ToolTransformParams& p) { return {p.d_m[0], p.d_m[1], p.d_m[2]}; }

/// A force f (N) acting at point q (sensor frame) seen by the sensor, by the base (the sensor's
/// pose in the base: mount) and in the tool frame placed in base coordinates.
struct PointForce {
  Eigen::Vector3d f, q;
};
Eigen::Matrix<double, 6, 1> AtFrame(const Eigen::Vector3d& f, const Eigen::Vector3d& q,
                                    const Eigen::Matrix3d& r, const Eigen::Vector3d& origin) {
  Eigen::Matrix<double, 6, 1> w;
  w.head<3>() = r.transpose() * f;
  w.tail<3>() = r.transpose() * (q - origin).cross(f);
  return w;
}

TEST(MountTransform, PointForcesMovedByRigidGeometryWithinOneLsb) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> ud(-0.6, 0.6), ua(-180, 180), uf(-400, 400), uq(-0.2, 0.2);
  for (int i = 0; i < 1000; ++i) {
    ToolTransformParams mount, tool;
    for (std::size_t k = 0; k < 3; ++k) {
      mount.d_m[k] = static_cast<float>(ud(rng));
      mount.r_deg[k] = static_cast<float>(ua(rng));
      tool.d_m[k] = i % 2 == 0 ? 0.0f : static_cast<float>(ud(rng));
      tool.r_deg[k] = i % 2 == 0 ? 0.0f : static_cast<float>(ua(rng));
    }
    FixedToolTransform t;
    ASSERT_EQ(MakeMountedToolTransform(tool, mount, &t), TransformStatus::kOk);
    const Eigen::Vector3d f(uf(rng), uf(rng), uf(rng)), q(uq(rng), uq(rng), uq(rng));
    const Eigen::Matrix<double, 6, 1> ws = AtFrame(f, q, Eigen::Matrix3d::Identity(), {0, 0, 0});
    WrenchLsb w{};
    for (std::size_t a = 0; a < kAxes; ++a) {
      w[a] = static_cast<std::int32_t>(std::lround(ws(static_cast<int>(a)) / AxisLsb(a)));
    }
    // The same force in the base: direction R_m·f at the point R_m·q + D_m; then the tool frame
    // (R_t, D_t) given in base coordinates.
    const Eigen::Matrix3d rm = Rot(mount);
    const Eigen::Vector3d fb = rm * f, qb = rm * q + D(mount);
    const Eigen::Matrix<double, 6, 1> ref = AtFrame(fb, qb, Rot(tool), D(tool));
    WrenchLsb y{};
    bool sat = false;
    ApplyToolTransform(t, w, &y, &sat);
    EXPECT_FALSE(sat);
    for (std::size_t a = 0; a < kAxes; ++a) {
      // Input rounding (≤ 0.5 LSB per axis, carried through a lever ≤ 2.2 m), coefficient and
      // output rounding: a few LSB.
      EXPECT_NEAR(y[a] * AxisLsb(a), ref(static_cast<int>(a)),
                  a < 3 ? 3e-3 : 0.25e-3 * 100 * 2.2 + 3e-5)
          << "axis " << a << " case " << i;
    }
  }
}

TEST(MountTransform, ZeroMountKeepsTheToolTransformBitForBit) {
  ToolTransformParams tool;
  tool.d_m = {0.01f, -0.2f, 0.3f};
  tool.r_deg = {10.0f, 20.0f, -30.0f};
  FixedToolTransform a, b;
  ASSERT_EQ(MakeToolTransform(tool, &a), TransformStatus::kOk);
  ASSERT_EQ(MakeMountedToolTransform(tool, ToolTransformParams{}, &b), TransformStatus::kOk);
  EXPECT_EQ(a.coef, b.coef);
  EXPECT_EQ(a.shift, b.shift);
  ToolTransformParams bad;
  bad.r_deg[1] = 361.0f;
  EXPECT_EQ(MakeMountedToolTransform(tool, bad, &b), TransformStatus::kOutOfRange);
}

using maptest::RegisterMapTest;

// Over the register map: a sensor 0.1 m below the base origin, turned 90° about z. A sensor Fx
// becomes base Fy, and about the base origin (0.1 m above the sensor) it has a moment.
TEST_F(RegisterMapTest, MountTransformWrittenOverModbusReportsTheBaseFrame) {
  StartDevice();
  adc_.counts = {300000, 0, 0, 0, 0, 0};
  EXPECT_EQ(WriteFloats(kHoldMount, {0.0f, 0.0f, -0.1f}), ModbusException::kIllegalDataValue);
  ASSERT_EQ(Write(kHoldUnlock, {kUnlockKey}), ModbusException::kNone);
  ASSERT_EQ(WriteFloats(kHoldMount, {0.0f, 0.0f, -0.1f, 0.0f, 0.0f, 90.0f}),
            ModbusException::kNone);
  EXPECT_EQ(Write(kHoldMount + 1, {0x3F80}), ModbusException::kIllegalDataValue);  // half a float
  Step();
  const auto r = Input();
  const double fx = ExpectedSi(0, 300000);
  const double tol = report_.worst_case_error_si[0] + std::fabs(fx) * 1e-6 + 2e-3;
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat]), 0.0, tol);
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 2]), fx, tol);
  // M_b = D_m × F_b = (0, 0, −0.1) × (0, Fx, 0) = (0.1·Fx, 0, 0).
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 6]), 0.1 * fx, 0.1 * tol + kMomentLsbNm);
  std::uint16_t h[12] = {};
  ASSERT_EQ(map_->ReadHolding(kHoldMount, 12, h), ModbusException::kNone);
  EXPECT_FLOAT_EQ(UnpackFloat32(&h[10]), 90.0f);
  EXPECT_EQ(map_->ReadHolding(kHoldingRegisterSpan, 1, h), ModbusException::kIllegalDataAddress);
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[kInPeaks + 2]), 0.0f);  // peaks stay in the sensor frame
}

}  // namespace
}  // namespace ftstack::fw
