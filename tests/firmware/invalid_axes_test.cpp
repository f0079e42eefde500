// Axes a calibration flags invalid (issue 17, item 16) at the register map: NaN / 0 and status bit
// 10 for them — in the tool frame for every axis the transform mixes them into, including the
// offset's d × F — their peaks NaN, and the other axes exact.
#include <gtest/gtest.h>

#include <cmath>

#include "firmware/register_map.hpp"
#include "tests/firmware/register_map_fixture.hpp"

namespace ftstack::fw {
namespace {

using maptest::RegisterMapTest;

float WrenchFloat(const std::array<std::uint16_t, kInputRegisterCount>& r, std::size_t axis) {
  return UnpackFloat32(&r[kInWrenchFloat + 2 * axis]);
}

TEST_F(RegisterMapTest, AxesFlaggedInvalidAreNeverServedAsValues) {
  cfg_.slots[0].fixed.invalid_axes = 1u << 0;  // Fx: its rig never loaded it
  StartDevice();
  adc_.counts = {400000, -300000, 1000000, 50000, -60000, 70000};
  Step(3);
  auto r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusAxisInvalid, kStatusAxisInvalid);
  EXPECT_EQ(r[kInStatus] & (kStatusCalInvalid | kStatusSaturated), 0);
  EXPECT_TRUE(std::isnan(WrenchFloat(r, 0)));
  EXPECT_EQ(UnpackI32(&r[kInWrenchInt]), 0);
  EXPECT_TRUE(std::isnan(UnpackFloat32(&r[kInPeaks])));
  for (std::size_t a = 1; a < 6; ++a) {
    const double si = ExpectedSi(a, adc_.counts[a]);
    EXPECT_NEAR(WrenchFloat(r, a), si, std::fabs(si) * 1e-6 + report_.worst_case_error_si[a]) << a;
    EXPECT_NEAR(UnpackFloat32(&r[kInPeaks + 2 * a]), std::fabs(si),
                std::fabs(si) * 1e-6 + report_.worst_case_error_si[a])
        << a;
  }
  // Tool origin 0.1 m up z: M' = M − d × F, and d × F = (−dz·Fy, dz·Fx, 0): the tool's My takes
  // the unknown Fx, its Mx only Fy. So Fx and My are invalid in the tool frame, Mx and Mz stay.
  ASSERT_EQ(Write(kHoldUnlock, {kUnlockKey}), ModbusException::kNone);
  ASSERT_EQ(WriteFloats(kHoldTransform, {0.0f, 0.0f, 0.1f}), ModbusException::kNone);
  Step(2);
  r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusAxisInvalid, kStatusAxisInvalid);
  EXPECT_TRUE(std::isnan(WrenchFloat(r, 0)));
  EXPECT_TRUE(std::isnan(WrenchFloat(r, 4)));
  EXPECT_EQ(UnpackI32(&r[kInWrenchInt + 8]), 0);
  for (const std::size_t a : {1u, 2u, 3u, 5u}) {
    EXPECT_FALSE(std::isnan(WrenchFloat(r, a))) << a;
  }
  // Mx' = Mx + dz·Fy (the sign of d × F taken out), both known.
  const double mx = ExpectedSi(3, adc_.counts[3]) + 0.1 * ExpectedSi(1, adc_.counts[1]);
  EXPECT_NEAR(std::fabs(WrenchFloat(r, 3)), std::fabs(mx), 1e-3);
  EXPECT_NEAR(WrenchFloat(r, 5), ExpectedSi(5, adc_.counts[5]), 1e-3);
  // Peaks stay in the sensor frame: only Fx's is invalid.
  EXPECT_TRUE(std::isnan(UnpackFloat32(&r[kInPeaks])));
  EXPECT_FALSE(std::isnan(UnpackFloat32(&r[kInPeaks + 8])));
}

}  // namespace
}  // namespace ftstack::fw
