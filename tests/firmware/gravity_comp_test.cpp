// Gravity compensation in the firmware: the integer subtraction against a double-precision
// reference (also at the range limits), and the holding registers 22–29 / input 77–84 through the
// register map and the device.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "firmware/gravity_comp.hpp"
#include "tests/firmware/register_map_fixture.hpp"

namespace ftstack::fw {
namespace {

struct Payload {
  double mass_kg;
  std::array<double, 3> com_m, fb_n, mb_nm;
};

/// The compensated wrench in LSB, in long double from the SI values.
std::array<long double, 6> Reference(const Payload& p, const std::array<double, 3>& g,
                                     const WrenchLsb& in) {
  std::array<long double, 6> out{};
  const long double m = p.mass_kg;
  const long double c[3] = {m * p.com_m[0], m * p.com_m[1], m * p.com_m[2]};
  const long double mom[3] = {c[1] * g[2] - c[2] * g[1], c[2] * g[0] - c[0] * g[2],
                              c[0] * g[1] - c[1] * g[0]};
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = in[i] - (m * g[i] + p.fb_n[i]) / kForceLsbN;
    out[3 + i] = in[3 + i] - (mom[i] + p.mb_nm[i]) / kMomentLsbNm;
  }
  return out;
}

TEST(GravityComp, MatchesADoublePrecisionReferenceWithinOneLsb) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> mass(0.01, 50.0), com(-0.5, 0.5), g(-12.0, 12.0),
      fb(-5, 5), mb(-0.5, 0.5);
  std::uniform_int_distribution<std::int32_t> w(-2000000, 2000000);
  for (int k = 0; k < 20000; ++k) {
    const Payload p{mass(rng),
                    {com(rng), com(rng), com(rng)},
                    {fb(rng), fb(rng), fb(rng)},
                    {mb(rng), mb(rng), mb(rng)}};
    FixedPayload fp{};
    ASSERT_EQ(MakeFixedPayload(p.mass_kg, p.com_m, p.fb_n, p.mb_nm, &fp), PayloadStatus::kOk);
    std::array<std::int32_t, 3> gi{};
    std::array<double, 3> gd{};
    for (std::size_t i = 0; i < 3; ++i) {
      const float gf = static_cast<float>(g(rng));
      ASSERT_TRUE(GravityToFixed(gf, &gi[i]));
      gd[i] = gf;
    }
    WrenchLsb in{};
    for (auto& v : in) v = w(rng);
    WrenchLsb out{};
    bool sat = false;
    CompensateGravity(fp, gi, in, &out, &sat);
    ASSERT_FALSE(sat);
    const auto ref = Reference(p, gd, in);
    // 0.5 LSB final rounding + 0.5 LSB bias rounding + the gravity's quantisation (0.5 µm/s²
    // per component): ≤ m·1e-6 N on a force (≪ 1 mN) and ≤ |m·c|·1e-6 N·m on a moment.
    double mc = 0;
    for (double c : p.com_m) mc = std::max(mc, std::fabs(p.mass_kg * c));
    for (std::size_t a = 0; a < 6; ++a) {
      const long double tol =
          1.0L + (a < 3 ? p.mass_kg * 1e-6 / kForceLsbN : mc * 1e-6 / kMomentLsbNm);
      ASSERT_LE(std::fabs(static_cast<long double>(out[a]) - ref[a]), tol)
          << "axis " << a << " trial " << k;
    }
  }
}

TEST(GravityComp, RangeLimitsNeitherOverflowNorLoseAccuracy) {
  // The largest payload and first moment at the largest gravity, every sign.
  for (double s : {1.0, -1.0}) {
    const Payload p{kMaxPayloadMassKg, {s * 1.0, -s * 1.0, s * 1.0}, {0, 0, 0}, {0, 0, 0}};
    FixedPayload fp{};
    ASSERT_EQ(MakeFixedPayload(p.mass_kg, p.com_m, p.fb_n, p.mb_nm, &fp), PayloadStatus::kOk);
    const std::array<std::int32_t, 3> gi = {kMaxGravityUmps2, -kMaxGravityUmps2, -kMaxGravityUmps2};
    const std::array<double, 3> gd = {20.0, -20.0, -20.0};
    const WrenchLsb in{};
    WrenchLsb out{};
    bool sat = false;
    CompensateGravity(fp, gi, in, &out, &sat);
    const auto ref = Reference(p, gd, in);
    EXPECT_FALSE(sat);
    for (std::size_t a = 0; a < 6; ++a) EXPECT_LE(std::fabs(out[a] - ref[a]), 0.5L) << a;
  }
  // A wrench at the int32 limit minus a weight clamps and says so.
  FixedPayload fp{};
  ASSERT_EQ(MakeFixedPayload(10, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, &fp), PayloadStatus::kOk);
  WrenchLsb in{};
  in[2] = std::numeric_limits<std::int32_t>::max();
  WrenchLsb out{};
  bool sat = false;
  CompensateGravity(fp, {0, 0, -9810000}, in, &out, &sat);
  EXPECT_TRUE(sat);
  EXPECT_EQ(out[2], std::numeric_limits<std::int32_t>::max());
}

TEST(GravityComp, RefusesUnusablePayloadsAndGravity) {
  FixedPayload fp{};
  EXPECT_EQ(MakeFixedPayload(NAN, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, &fp), PayloadStatus::kNotFinite);
  EXPECT_EQ(MakeFixedPayload(0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, &fp), PayloadStatus::kOutOfRange);
  EXPECT_EQ(MakeFixedPayload(101, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, &fp),
            PayloadStatus::kOutOfRange);
  EXPECT_EQ(MakeFixedPayload(50, {3, 0, 0}, {0, 0, 0}, {0, 0, 0}, &fp), PayloadStatus::kOutOfRange);
  EXPECT_FALSE(fp.present);
  std::int32_t g = 7;
  EXPECT_FALSE(GravityToFixed(NAN, &g));
  EXPECT_FALSE(GravityToFixed(INFINITY, &g));
  EXPECT_FALSE(GravityToFixed(20.01f, &g));
  EXPECT_EQ(g, 7);
  EXPECT_TRUE(GravityToFixed(-9.80665f, &g));
  EXPECT_EQ(g, -9806650);
}

class GravityMapTest : public maptest::RegisterMapTest {};

TEST_F(GravityMapTest, WithoutAPayloadCompensationIsRefusedAndGravityStillRoundTrips) {
  StartDevice();
  EXPECT_EQ(Write(kHoldGravityComp, {1}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldGravityComp), 0);
  ASSERT_EQ(WriteFloats(kHoldGravity, {0.5f, -1.25f, -9.5f}), ModbusException::kNone);
  std::array<std::uint16_t, 6> r{};
  ASSERT_EQ(map_->ReadHolding(kHoldGravity, 6, r.data()), ModbusException::kNone);
  EXPECT_EQ(UnpackFloat32(&r[4]), -9.5f);
  EXPECT_EQ(Input()[kInPayloadMass], 0);
  EXPECT_EQ(UnpackU32(&Input()[kInPayloadCrc]), 0u);
}

TEST_F(GravityMapTest, BadGravityWritesChangeNothing) {
  StartDevice();
  ASSERT_EQ(WriteFloats(kHoldGravity, {1.0f, 2.0f, -9.0f}), ModbusException::kNone);
  EXPECT_EQ(WriteFloats(kHoldGravity, {1.0f, NAN, -9.0f}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(WriteFloats(kHoldGravity + 2, {25.0f}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldGravity + 1, {0}), ModbusException::kIllegalDataValue);  // half a float
  EXPECT_EQ(Write(kHoldReserved29, {1}), ModbusException::kIllegalDataValue);
  std::array<std::uint16_t, 6> r{};
  ASSERT_EQ(map_->ReadHolding(kHoldGravity, 6, r.data()), ModbusException::kNone);
  EXPECT_EQ(UnpackFloat32(&r[0]), 1.0f);
  EXPECT_EQ(UnpackFloat32(&r[2]), 2.0f);
  EXPECT_EQ(UnpackFloat32(&r[4]), -9.0f);
}

TEST_F(GravityMapTest, ThePayloadIsSubtractedBeforeTheToolTransformWhenSwitchedOn) {
  const Payload p{1.6, {0.01, -0.02, 0.05}, {0.3, -0.2, 0.1}, {0.01, 0.02, -0.03}};
  ASSERT_EQ(MakeFixedPayload(p.mass_kg, p.com_m, p.fb_n, p.mb_nm, &cfg_.payload),
            PayloadStatus::kOk);
  cfg_.payload_crc = 0x11223344u;
  StartDevice();
  adc_.counts = {400000, -300000, 1000000, 50000, -60000, 70000};
  Step(2);
  const auto before = Input();
  EXPECT_EQ(before[kInStatus] & kStatusPayloadComp, 0);
  EXPECT_FLOAT_EQ(UnpackFloat32(&before[kInPayloadMass]), 1.6f);
  EXPECT_EQ(UnpackU32(&before[kInPayloadCrc]), 0x11223344u);
  const std::array<float, 3> g = {3.0f, -4.0f, -8.3f};
  ASSERT_EQ(WriteFloats(kHoldGravity, {g[0], g[1], g[2]}), ModbusException::kNone);
  ASSERT_EQ(Write(kHoldGravityComp, {1}), ModbusException::kNone);
  // A tool frame 0.1 m along z: the compensation must happen in the sensor frame first.
  const std::uint16_t key = kUnlockKey;
  ASSERT_EQ(map_->WriteHolding(kHoldUnlock, &key, 1), ModbusException::kNone);
  ASSERT_EQ(WriteFloats(kHoldTransform, {0.0f, 0.0f, 0.1f}), ModbusException::kNone);
  Step(2);
  const auto after = Input();
  EXPECT_NE(after[kInStatus] & kStatusPayloadComp, 0);
  const std::array<double, 3> gd = {g[0], g[1], g[2]};
  WrenchLsb sensor{};
  for (std::size_t a = 0; a < 6; ++a) {
    sensor[a] = static_cast<std::int32_t>(std::llround(ExpectedSi(a, adc_.counts[a]) / AxisLsb(a)));
  }
  const auto comp = Reference(p, gd, sensor);
  double f[3], m[3];
  for (std::size_t i = 0; i < 3; ++i) {
    f[i] = static_cast<double>(comp[i]) * kForceLsbN;
    m[i] = static_cast<double>(comp[3 + i]) * kMomentLsbNm;
  }
  // Tool point D = (0, 0, 0.1): M_tool = M − D × F.
  const double mt[3] = {m[0] + 0.1 * f[1], m[1] - 0.1 * f[0], m[2]};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(UnpackFloat32(&after[kInWrenchFloat + 2 * i]), f[i], 3e-3) << i;
    EXPECT_NEAR(UnpackFloat32(&after[kInWrenchFloat + 6 + 2 * i]), mt[i], 3e-5) << i;
  }
  ASSERT_EQ(Write(kHoldGravityComp, {0}), ModbusException::kNone);
  Step(1);
  EXPECT_EQ(Input()[kInStatus] & kStatusPayloadComp, 0);
}

}  // namespace
}  // namespace ftstack::fw
