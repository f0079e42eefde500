// Register map, overload rule, tool transform and seqlock, against double-precision references.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "firmware/register_map.hpp"
#include "hal/sim/sim_adc.hpp"
#include "tests/firmware/fake_adc.hpp"
#include "tests/firmware/register_map_fixture.hpp"

namespace ftstack::fw {
namespace {

using maptest::g_now_us;
using maptest::kGain;
using maptest::kMvvPerCount;
using maptest::kRatedLsb;
using maptest::RegisterMapTest;

// ---------------------------------------------------------------------------------------------
// Packing: published IEEE-754 and two's-complement bit patterns, high word first.

TEST(ModbusPacking, Float32HighWordFirstMatchesIeeeBitPattern) {
  std::uint16_t r[2];
  PackFloat32(3.5f, r);  // 3.5 = 0x40600000
  EXPECT_EQ(r[0], 0x4060);
  EXPECT_EQ(r[1], 0x0000);
  PackFloat32(-0.1f, r);  // -0.1f = 0xBDCCCCCD
  EXPECT_EQ(r[0], 0xBDCC);
  EXPECT_EQ(r[1], 0xCCCD);
  PackI32(-2, r);
  EXPECT_EQ(r[0], 0xFFFF);
  EXPECT_EQ(r[1], 0xFFFE);
  PackU32(0x12345678u, r);
  EXPECT_EQ(r[0], 0x1234);
  EXPECT_EQ(r[1], 0x5678);
}

TEST(ModbusPacking, RoundTripsEveryBitPattern) {
  std::mt19937 rng(7);
  for (int i = 0; i < 100000; ++i) {
    const std::uint32_t u = rng();
    std::uint16_t r[2];
    PackU32(u, r);
    EXPECT_EQ(UnpackU32(r), u);
    float f;
    std::memcpy(&f, &u, 4);
    PackFloat32(f, r);
    const float g = UnpackFloat32(r);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(g), u);  // bit for bit, NaN payloads included
    PackI32(static_cast<std::int32_t>(u), r);
    EXPECT_EQ(UnpackI32(r), static_cast<std::int32_t>(u));
  }
}

// ---------------------------------------------------------------------------------------------
// Overload rule.

TEST(Overload, IntegerSquareRootIsExactFloor) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t n = rng() >> (rng() % 64);
    const std::uint64_t r = ISqrt64(n);
    EXPECT_LE(r * r, n);
    EXPECT_GT((r + 1) * (r + 1), n);  // r + 1 ≤ 2^32: the square fits unless r = 2^32 - 1
  }
  EXPECT_EQ(ISqrt64(std::numeric_limits<std::uint64_t>::max()), 0xFFFFFFFFu);
  EXPECT_EQ(ISqrt64(0), 0u);
}

struct RefShares {
  double fxy_mz, fz_mxy;
};
RefShares ReferenceShares(const WrenchLsb& w) {
  auto s = [&](std::size_t i) { return std::fabs(static_cast<double>(w[i])) / kRatedLsb[i]; };
  return {std::hypot(s(0), s(1)) + s(5), s(2) + std::hypot(s(3), s(4))};
}

TEST(Overload, SharesMatchDoubleReferenceAndDecideAt105Percent) {
  OverloadMonitor m;
  ASSERT_TRUE(m.Configure(kRatedLsb));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  int over = 0;
  for (int i = 0; i < 50000; ++i) {
    WrenchLsb w{};
    for (std::size_t a = 0; a < kAxes; ++a) {
      w[a] = static_cast<std::int32_t>(std::lround(u(rng) * 0.7 * kRatedLsb[a]));
    }
    const RefShares ref = ReferenceShares(w);
    const LoadShares got = m.Shares(w);
    // Q24 with floor(2^48/R) reciprocals: each share is low by less than 3 units of 2^-24.
    EXPECT_NEAR(got.fxy_mz / 16777216.0, ref.fxy_mz, 4.0 / 16777216.0);
    EXPECT_NEAR(got.fz_mxy / 16777216.0, ref.fz_mxy, 4.0 / 16777216.0);
    const double worst = std::max(ref.fxy_mz, ref.fz_mxy);
    if (std::fabs(worst - 1.05) < 1e-6) continue;  // inside the rounding band
    OverloadMonitor fresh;
    ASSERT_TRUE(fresh.Configure(kRatedLsb));
    EXPECT_EQ(fresh.Update(w), worst > 1.05) << "shares " << ref.fxy_mz << " " << ref.fz_mxy;
    over += worst > 1.05 ? 1 : 0;
  }
  EXPECT_GT(over, 1000);  // both outcomes were exercised
  EXPECT_LT(over, 49000);
}

TEST(Overload, PureAxisLoadsTripJustAbove105Percent) {
  OverloadMonitor m;
  ASSERT_TRUE(m.Configure(kRatedLsb));
  for (std::size_t a = 0; a < kAxes; ++a) {
    WrenchLsb w{};
    w[a] = static_cast<std::int32_t>(kRatedLsb[a] * 1.049);
    EXPECT_FALSE(m.Update(w)) << "axis " << a;
    w[a] = -static_cast<std::int32_t>(kRatedLsb[a] * 1.051);
    EXPECT_TRUE(m.Update(w)) << "axis " << a;
    m.Update(WrenchLsb{});
  }
  // 60 % Fx + 50 % Mz = 110 % of the shear capacity; 60 % + 40 % = 100 % is fine.
  WrenchLsb w{};
  w[0] = 120000;
  w[5] = 320000;
  EXPECT_FALSE(m.Update(w));
  w[5] = 400000;
  EXPECT_TRUE(m.Update(w));
}

TEST(Overload, CountsEventsOnEntryAndTracksPeaksUntilCleared) {
  OverloadMonitor m;
  ASSERT_TRUE(m.Configure(kRatedLsb));
  const WrenchLsb calm = {1000, -2000, 3000, -4000, 5000, -6000};
  const WrenchLsb over = {0, 0, -500000, 0, 0, 0};
  const WrenchLsb spike = {-150000, 0, 0, 0, 0, 0};
  for (const WrenchLsb& w : {calm, over, over, calm, over, spike, calm}) (void)m.Update(w);
  EXPECT_EQ(m.events(), 2u);
  const WrenchLsb expected_peaks = {150000, 2000, 500000, 4000, 5000, 6000};
  EXPECT_EQ(m.peaks(), expected_peaks);
  m.Clear();
  EXPECT_EQ(m.events(), 0u);
  EXPECT_EQ(m.peaks(), WrenchLsb{});
  EXPECT_FALSE(m.Configure(WrenchLsb{1, 1, 1, 1, 1, 0}));
  EXPECT_FALSE(m.Configure(WrenchLsb{1, 1, 1, 1, 1, kMaxRatedLsb + 1}));
}

// ---------------------------------------------------------------------------------------------
// Tool transform.

Eigen::Matrix<double, 6, 1> ReferenceTransform(const ToolTransformParams& p,
                                               const Eigen::Matrix<double, 6, 1>& w_si) {
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(p.r_deg[2] * kDeg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(p.r_deg[1] * kDeg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(p.r_deg[0] * kDeg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d d(p.d_m[0], p.d_m[1], p.d_m[2]);
  const Eigen::Vector3d f = w_si.head<3>();
  const Eigen::Vector3d m = w_si.tail<3>();
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = r.transpose() * f;
  out.tail<3>() = r.transpose() * (m - d.cross(f));
  return out;
}

TEST(ToolTransform, MatchesDoubleReferenceWithinOneLsb) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ud(-0.5, 0.5), ua(-180, 180), uf(-400, 400), um(-10, 10);
  for (int i = 0; i < 2000; ++i) {
    ToolTransformParams p;
    for (std::size_t k = 0; k < 3; ++k) {
      p.d_m[k] = static_cast<float>(ud(rng));
      p.r_deg[k] = static_cast<float>(ua(rng));
    }
    FixedToolTransform t;
    ASSERT_EQ(MakeToolTransform(p, &t), TransformStatus::kOk);
    WrenchLsb w{};
    Eigen::Matrix<double, 6, 1> w_si;
    for (std::size_t a = 0; a < kAxes; ++a) {
      const double v = a < 3 ? uf(rng) : um(rng);
      w[a] = static_cast<std::int32_t>(std::lround(v / AxisLsb(a)));
      w_si(static_cast<int>(a)) = w[a] * AxisLsb(a);  // the exact input the firmware sees
    }
    WrenchLsb y{};
    bool sat = false;
    ApplyToolTransform(t, w, &y, &sat);
    EXPECT_FALSE(sat);
    const Eigen::Matrix<double, 6, 1> ref = ReferenceTransform(p, w_si);
    for (std::size_t a = 0; a < kAxes; ++a) {
      // Final rounding (0.5 LSB) plus each coefficient's rounding (half a unit of 2^-shift)
      // times its input.
      double bound = 0.5;
      for (std::size_t j = 0; j < kAxes; ++j) {
        bound += 0.5 * std::ldexp(std::fabs(w[j]), -t.shift[a]);
      }
      EXPECT_NEAR(y[a], ref(static_cast<int>(a)) / AxisLsb(a), bound + 1e-9) << "axis " << a;
      EXPECT_LT(bound, 0.75);  // and the bound itself is tight: well under one LSB extra
    }
  }
}

TEST(ToolTransform, ForceAtTheToolPointHasNoMomentThere) {
  // 10 N along x applied at D = (0, 0, 0.1) m: the sensor sees My = +1 N·m; at the tool point
  // the moment vanishes.
  ToolTransformParams p;
  p.d_m = {0.0f, 0.0f, 0.1f};
  FixedToolTransform t;
  ASSERT_EQ(MakeToolTransform(p, &t), TransformStatus::kOk);
  const WrenchLsb w = {10000, 0, 0, 0, 100000, 0};
  WrenchLsb y{};
  bool sat = false;
  ApplyToolTransform(t, w, &y, &sat);
  EXPECT_EQ(y, (WrenchLsb{10000, 0, 0, 0, 0, 0}));
  // Rz = 90°: the tool x axis is the sensor y axis, so a sensor +Fx is a tool −Fy.
  p = {};
  p.r_deg = {0.0f, 0.0f, 90.0f};
  ASSERT_EQ(MakeToolTransform(p, &t), TransformStatus::kOk);
  ApplyToolTransform(t, WrenchLsb{1000, 0, 0, 0, 0, 0}, &y, &sat);
  EXPECT_EQ(y, (WrenchLsb{0, -1000, 0, 0, 0, 0}));
}

TEST(ToolTransform, RefusesNonFiniteAndOutOfRangeAndLeavesOutputAlone) {
  FixedToolTransform t;
  t.identity = false;
  t.shift[0] = 7;
  ToolTransformParams p;
  p.d_m[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(MakeToolTransform(p, &t), TransformStatus::kNotFinite);
  p = {};
  p.r_deg[2] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(MakeToolTransform(p, &t), TransformStatus::kNotFinite);
  p = {};
  p.d_m[0] = 10.5f;
  EXPECT_EQ(MakeToolTransform(p, &t), TransformStatus::kOutOfRange);
  p = {};
  p.r_deg[0] = -361.0f;
  EXPECT_EQ(MakeToolTransform(p, &t), TransformStatus::kOutOfRange);
  EXPECT_FALSE(t.identity);
  EXPECT_EQ(t.shift[0], 7);
  // The largest transform accepted cannot overflow the accumulator for any int32 input.
  p.d_m = {10.0f, -10.0f, 10.0f};
  p.r_deg = {33.0f, -71.0f, 150.0f};
  ASSERT_EQ(MakeToolTransform(p, &t), TransformStatus::kOk);
  for (std::size_t r = 0; r < kAxes; ++r) {
    double bound = 0;
    for (std::size_t j = 0; j < kAxes; ++j) bound += std::fabs(static_cast<double>(t.coef[r][j]));
    EXPECT_LE(bound * 2147483648.0, std::ldexp(1.0, 62)) << "row " << r;
  }
}

// ---------------------------------------------------------------------------------------------
// Seqlock: concurrent readers never see a mix of two writes.

struct Stamped {
  std::uint32_t seq;
  std::array<std::int64_t, 24> payload;
};

TEST(Seqlock, ReadersNeverSeeTornValues) {
  Seqlock<Stamped> lock;
  std::atomic<bool> done{false};
  std::atomic<std::uint32_t> pause_sink{0};
  std::thread writer([&] {
    Stamped s{};
    for (std::uint32_t i = 1; i <= 200000; ++i) {
      s.seq = i;
      for (std::size_t k = 0; k < s.payload.size(); ++k) {
        s.payload[k] = std::int64_t{i} * 1000003 + static_cast<std::int64_t>(k);
      }
      lock.Write(s);
      // A sampling thread pauses between samples; it busy-waits here rather than yielding, as a
      // yield hands its core to a spinning reader for a whole time slice on a 2-core machine
      // (40 s for this test instead of under a second).
      for (int k = 0; k < 64; ++k) pause_sink.fetch_add(1, std::memory_order_relaxed);
    }
    done = true;
  });
  std::atomic<int> torn{0}, backwards{0}, reads{0};
  auto reader = [&] {
    std::uint32_t last = 0;
    while (!done) {
      Stamped s{};
      if (!lock.Read(&s)) continue;
      ++reads;
      for (std::size_t k = 0; k < s.payload.size(); ++k) {
        if (s.payload[k] != std::int64_t{s.seq} * 1000003 + static_cast<std::int64_t>(k) &&
            s.seq != 0) {
          ++torn;
          break;
        }
      }
      if (s.seq < last) ++backwards;
      last = s.seq;
    }
  };
  std::thread r1(reader), r2(reader);
  writer.join();
  r1.join();
  r2.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_EQ(backwards.load(), 0);
  EXPECT_GT(reads.load(), 100);
}

// ---------------------------------------------------------------------------------------------
// Register map over a Device driven by a scripted ADC.

TEST_F(RegisterMapTest, InputImageCarriesOneSampleInTheSpecifiedLayout) {
  StartDevice();
  adc_.counts = {400000, -300000, 1000000, 50000, -60000, 70000};
  Step(3);
  const auto r = Input();
  EXPECT_EQ(r[kInMapVersion], 3);
  EXPECT_EQ(r[kInStatus], 0);  // real (fake) hardware, calibrated, no faults
  EXPECT_EQ(UnpackU32(&r[kInSequence]), 3u);
  EXPECT_EQ(UnpackU32(&r[kInTimestampUs]), 2000u);
  for (std::size_t a = 0; a < kAxes; ++a) {
    const double si = ExpectedSi(a, adc_.counts[a]);
    const double tol = report_.worst_case_error_si[a] + std::fabs(si) * 6e-8;
    EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 2 * a]), si, tol) << "axis " << a;
    // int32 registers: mN and mN·m, rounded: within 0.5 unit + the fixed-point error.
    EXPECT_NEAR(UnpackI32(&r[kInWrenchInt + 2 * a]), si * 1e3,
                0.5 + report_.worst_case_error_si[a] * 1e3)
        << "axis " << a;
    EXPECT_EQ(UnpackI32(&r[kInRawCounts + 2 * a]), adc_.counts[a]);
    EXPECT_NEAR(UnpackFloat32(&r[kInBridgeMvv + 2 * a]), adc_.counts[a] * kMvvPerCount,
                std::fabs(adc_.counts[a] * kMvvPerCount) * 6e-8);
    // Peaks: the largest |unfiltered| value seen, sensor frame.
    EXPECT_NEAR(UnpackFloat32(&r[kInPeaks + 2 * a]), std::fabs(si), tol);
  }
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[kInTemperature]), 20.0f);
  EXPECT_EQ(r[kInBridgeCount], 6);
  EXPECT_EQ(r[kInCalSlot], 0);
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 0u);
  EXPECT_EQ(UnpackU32(&r[kInCalCrc]), 0xCAFEF00Du);
}

TEST_F(RegisterMapTest, StaleBitAfterTwoPeriodsWithoutSample) {
  StartDevice();
  Step(2);
  g_now_us += 1000;  // 2 periods since the last publication (Step advanced 1000 already)
  EXPECT_EQ(Input()[kInStatus] & kStatusStale, 0);
  g_now_us += 1;
  EXPECT_NE(Input()[kInStatus] & kStatusStale, 0);
  Step();
  EXPECT_EQ(Input()[kInStatus] & kStatusStale, 0);
}

TEST_F(RegisterMapTest, AddressesOutsideTheMapGiveException02) {
  StartDevice();
  std::array<std::uint16_t, 125> buf{};
  EXPECT_EQ(map_->ReadInput(84, 1, buf.data()), ModbusException::kNone);
  EXPECT_EQ(map_->ReadInput(199, 1, buf.data()), ModbusException::kNone);  // map v3: 0 … 385
  EXPECT_EQ(map_->ReadInput(209, 2, buf.data()), ModbusException::kNone);
  EXPECT_EQ(map_->ReadInput(385, 1, buf.data()), ModbusException::kNone);
  EXPECT_EQ(map_->ReadInput(385, 2, buf.data()), ModbusException::kIllegalDataAddress);
  EXPECT_EQ(map_->ReadInput(386, 1, buf.data()), ModbusException::kIllegalDataAddress);
  EXPECT_EQ(map_->ReadHolding(0, 5, buf.data()), ModbusException::kNone);
  EXPECT_EQ(map_->ReadHolding(10, 12, buf.data()), ModbusException::kNone);
  // 5 … 9 are reserved, not a hole: a PLC's block read of 0 … 15 or 0 … 21 works.
  buf.fill(0xFFFF);
  EXPECT_EQ(map_->ReadHolding(0, 16, buf.data()), ModbusException::kNone);
  EXPECT_EQ(map_->ReadHolding(0, 22, buf.data()), ModbusException::kNone);
  for (std::uint16_t a = 5; a < 10; ++a) {
    EXPECT_EQ(buf[a], 0) << a;
    EXPECT_EQ(Write(a, {1}), ModbusException::kIllegalDataValue);
    EXPECT_EQ(Write(a, {0}), ModbusException::kNone);
  }
  EXPECT_EQ(map_->ReadHolding(0, 80, buf.data()), ModbusException::kNone);  // map v3: 0 … 79
  EXPECT_EQ(map_->ReadHolding(79, 2, buf.data()), ModbusException::kIllegalDataAddress);
  EXPECT_EQ(Write(80, {0}), ModbusException::kIllegalDataAddress);
  EXPECT_EQ(Write(65535, {0}), ModbusException::kIllegalDataAddress);
}

TEST_F(RegisterMapTest, MqttBlockReadsThePublishersCountersAlsoInAReadAcrossBlocks) {
  StartDevice();
  std::array<std::uint16_t, 125> buf{};
  buf.fill(0xFFFF);
  ASSERT_EQ(map_->ReadInput(kInMqttFirst, kInMqttCount, buf.data()), ModbusException::kNone);
  for (std::uint16_t i = 0; i < kInMqttCount; ++i) EXPECT_EQ(buf[i], 0) << "unset, " << i;
  MqttCounters c;
  c.connected = 1;
  c.published = 0x12345678u;
  c.dropped = 0xFFFFFFFFu;
  c.reconnects = 65536;
  map_->SetMqttCounters(&c);
  ASSERT_EQ(map_->ReadInput(kInMqttFirst, kInMqttCount, buf.data()), ModbusException::kNone);
  const std::array<std::uint16_t, 10> want = {1, 0x1234, 0x5678, 0xFFFF, 0xFFFF, 1, 0, 0, 0, 0};
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(buf[i], want[i]) << 200 + i;
  ASSERT_EQ(map_->ReadInput(205, 2, buf.data()), ModbusException::kNone);
  EXPECT_EQ(UnpackU32(buf.data()), 65536u);
  // A read across the sample image and the MQTT block: the health block's last registers (read
  // alone as the reference) followed by the counters.
  std::array<std::uint16_t, 125> alone{};
  ASSERT_EQ(map_->ReadInput(190, 10, alone.data()), ModbusException::kNone);
  buf.fill(0xFFFF);
  ASSERT_EQ(map_->ReadInput(190, 20, buf.data()), ModbusException::kNone);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(buf[i], alone[i]) << 190 + i;
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(buf[10 + i], want[i]) << 200 + i;
  // … and across the MQTT block and the history block (read alone as the reference).
  ASSERT_EQ(map_->ReadInput(kInHistoryFirst, 10, alone.data()), ModbusException::kNone);
  buf.fill(0xFFFF);
  ASSERT_EQ(map_->ReadInput(kInMqttFirst, 20, buf.data()), ModbusException::kNone);
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(buf[i], want[i]) << 200 + i;
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(buf[10 + i], alone[i]) << 210 + i;
  for (const auto& [addr, count] :
       std::vector<std::pair<int, int>>{{385, 2}, {386, 1}, {200, 187}, {0, 387}}) {
    EXPECT_EQ(map_->ReadInput(static_cast<std::uint16_t>(addr), static_cast<std::uint16_t>(count),
                              buf.data()),
              ModbusException::kIllegalDataAddress)
        << addr << "+" << count;
  }
}

TEST_F(RegisterMapTest, ValuesOutOfRangeGive03AndChangeNothing) {
  StartDevice();
  EXPECT_EQ(Holding(kHoldFilterLength), 1);
  EXPECT_EQ(Write(kHoldFilterLength, {0}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldFilterLength, {257}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldFilterLength, {256}), ModbusException::kNone);
  EXPECT_EQ(Holding(kHoldFilterLength), 256);
  EXPECT_EQ(Write(kHoldDecimation, {0}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldDecimation, {1001}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldCommand, {4}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldCommand, {0}), ModbusException::kNone);  // what it reads: no command
  EXPECT_EQ(Write(kHoldUnlock, {0x1234}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldUnlock), 0);
  // A multi-register write with one bad value changes nothing, not even the good ones before it.
  EXPECT_EQ(Write(kHoldCommand, {kCmdTare, 10, 0}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldFilterLength), 256);
  EXPECT_EQ(Holding(kHoldDecimation), 1);
  Step(10);
  EXPECT_EQ(Input()[kInStatus] & kStatusTareActive, 0);  // the tare never started
  EXPECT_EQ(Holding(kHoldCommand), 0);
}

TEST_F(RegisterMapTest, ProtectedWritesNeedUnlockAndExpireAfterTenSeconds) {
  cfg_.slots[1] = cfg_.slots[0];
  cfg_.slots[1].crc32 = 0x0BADBEEFu;
  StartDevice();
  EXPECT_EQ(Write(kHoldCalSlot, {1}), ModbusException::kIllegalDataValue);  // locked
  EXPECT_EQ(WriteFloats(kHoldTransform, {0.1f}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldCalSlot), 0);
  EXPECT_EQ(Holding(kHoldTransform), 0);
  EXPECT_EQ(Write(kHoldUnlock, {kUnlockKey}), ModbusException::kNone);
  EXPECT_EQ(Holding(kHoldUnlock), 1);
  EXPECT_EQ(Write(kHoldCalSlot, {2}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldCalSlot, {1}), ModbusException::kNone);
  Step();
  auto r = Input();
  EXPECT_EQ(r[kInCalSlot], 1);
  EXPECT_EQ(UnpackU32(&r[kInCalCrc]), 0x0BADBEEFu);
  // Half a float is refused; so is a NaN; the registers keep their previous content.
  EXPECT_EQ(Write(kHoldTransform + 1, {0x3F80}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldTransform, {0x3F80}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(WriteFloats(kHoldTransform, {std::numeric_limits<float>::quiet_NaN()}),
            ModbusException::kIllegalDataValue);
  EXPECT_EQ(WriteFloats(kHoldTransform + 6, {0.0f, 0.0f, 400.0f}),
            ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldTransform), 0);
  EXPECT_EQ(WriteFloats(kHoldTransform, {0.0f, 0.0f, 0.1f}), ModbusException::kNone);
  EXPECT_FLOAT_EQ(UnpackFloat32(std::array<std::uint16_t, 2>{Holding(14), Holding(15)}.data()),
                  0.1f);
  g_now_us += kUnlockDurationUs;
  EXPECT_EQ(Holding(kHoldUnlock), 0);
  EXPECT_EQ(Write(kHoldCalSlot, {0}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Holding(kHoldCalSlot), 1);
}

TEST_F(RegisterMapTest, MissingCalibrationSlotCannotBeSelected) {
  StartDevice();
  EXPECT_EQ(Write(kHoldUnlock, {kUnlockKey}), ModbusException::kNone);
  EXPECT_EQ(Write(kHoldCalSlot, {1}), ModbusException::kIllegalDataValue);
  EXPECT_EQ(Write(kHoldCalSlot, {0}), ModbusException::kNone);
}

TEST_F(RegisterMapTest, ToolTransformWrittenOverModbusMovesTheWrench) {
  StartDevice();
  adc_.counts = {300000, 0, 0, 0, 0, 0};  // Fx only
  ASSERT_EQ(Write(kHoldUnlock, {kUnlockKey}), ModbusException::kNone);
  ASSERT_EQ(WriteFloats(kHoldTransform, {0.0f, 0.0f, 0.2f, 0.0f, 0.0f, 0.0f}),
            ModbusException::kNone);
  Step();
  const auto r = Input();
  const double fx = ExpectedSi(0, 300000);
  // At a tool point 0.2 m along z the force Fx has moment M = −D × F: My = −0.2·Fx.
  // Fx carries the core's fixed-point error (report_); My = −0.2·Fx inherits 0.2 of it, plus half
  // an output LSB and float32 rounding.
  const double fx_tol = report_.worst_case_error_si[0] + std::fabs(fx) * 6e-8;
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat]), fx, fx_tol);
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 8]), -0.2 * fx,
              0.2 * fx_tol + 0.5 * kMomentLsbNm + 0.2 * std::fabs(fx) * 6e-8);
  // Peaks stay in the sensor frame (what the rating refers to): My peak 0.
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[kInPeaks + 8]), 0.0f);
}

TEST_F(RegisterMapTest, CommandsTareClearTareAndClearPeaks) {
  StartDevice();
  adc_.counts = {200000, 0, 500000, 0, 0, 0};
  Step(2);
  ASSERT_EQ(Write(kHoldCommand, {kCmdTare}), ModbusException::kNone);
  Step(cfg_.tare_samples + 1);
  auto r = Input();
  EXPECT_NE(r[kInStatus] & kStatusTareActive, 0);
  for (std::size_t a = 0; a < kAxes; ++a) EXPECT_EQ(UnpackI32(&r[kInWrenchInt + 2 * a]), 0);
  ASSERT_EQ(Write(kHoldCommand, {kCmdClearTare}), ModbusException::kNone);
  Step();
  r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusTareActive, 0);
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 4]), ExpectedSi(2, 500000), 2e-3);
  // Overload: Fz at 1.1 × rated (440 N) is one event and sets bit 1 while it lasts.
  adc_.counts[2] = static_cast<std::int32_t>(440.0 / kGain[2] / kMvvPerCount);
  Step(3);
  r = Input();
  EXPECT_NE(r[kInStatus] & kStatusOverload, 0);
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 1u);
  EXPECT_NEAR(UnpackFloat32(&r[kInPeaks + 4]), 440.0, 0.01);
  adc_.counts[2] = 0;
  Step();
  r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusOverload, 0);
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 1u);
  ASSERT_EQ(Write(kHoldCommand, {kCmdClearPeaks}), ModbusException::kNone);
  Step();
  r = Input();
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 0u);
  EXPECT_NEAR(UnpackFloat32(&r[kInPeaks]), ExpectedSi(0, 200000), 2e-3);  // this sample's Fx
  EXPECT_FLOAT_EQ(UnpackFloat32(&r[kInPeaks + 4]), 0.0f);
}

TEST_F(RegisterMapTest, DecimationPublishesEveryNthSample) {
  StartDevice();
  ASSERT_EQ(Write(kHoldDecimation, {4}), ModbusException::kNone);
  Step(12);
  auto r = Input();
  EXPECT_EQ(UnpackU32(&r[kInSequence]), 3u);
  EXPECT_EQ(UnpackU32(&r[kInTimestampUs]), 11000u);
  // Stale is judged on samples read, not on publications: between publications of a large
  // decimation nothing is stale while samples keep coming; 2 sample periods without one is.
  Step(2);  // samples 13 and 14: not published
  EXPECT_EQ(Input()[kInStatus] & kStatusStale, 0);
  g_now_us += 1000;  // the last sample is 2 periods old
  EXPECT_EQ(Input()[kInStatus] & kStatusStale, 0);
  g_now_us += 1;
  EXPECT_NE(Input()[kInStatus] & kStatusStale, 0);
}

TEST_F(RegisterMapTest, LateSamplesAreCountedAndFlagged) {
  StartDevice();
  Step(5);
  auto r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusLate, 0);
  EXPECT_EQ(UnpackU32(&r[kInLateSamples]), 0u);
  g_now_us += 3000;  // the sampling thread was descheduled: read 4 periods after the previous
  Step();
  r = Input();
  EXPECT_NE(r[kInStatus] & kStatusLate, 0);
  EXPECT_EQ(UnpackU32(&r[kInLateSamples]), 3u);  // three deadlines missed
  Step();
  r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusLate, 0);  // on time again; the counter keeps the history
  EXPECT_EQ(UnpackU32(&r[kInLateSamples]), 3u);
  g_now_us += 400;  // 1.4 periods: jitter, not late
  Step();
  EXPECT_EQ(Input()[kInStatus] & kStatusLate, 0);
}

TEST_F(RegisterMapTest, FaultsSaturationInvalidatesTheWrenchAndAdcTimeoutFlags) {
  StartDevice();
  adc_.counts = {100000, 0, 0, 0, 0, 0};
  Step();
  const float fx = UnpackFloat32(&Input()[kInWrenchFloat]);
  adc_.counts[3] = (1 << 23) - 1;  // at the rail
  Step();
  auto r = Input();
  EXPECT_NE(r[kInStatus] & kStatusSaturated, 0);
  EXPECT_TRUE(std::isnan(UnpackFloat32(&r[kInWrenchFloat])));  // no held value served as true
  EXPECT_EQ(UnpackI32(&r[kInWrenchInt]), 0);
  adc_.counts[3] = 0;
  Step();
  r = Input();
  EXPECT_EQ(r[kInStatus] & kStatusSaturated, 0);
  EXPECT_EQ(UnpackFloat32(&r[kInWrenchFloat]), fx);
  adc_.next_status = hal::Status::kTimeout;
  bool published = false;
  EXPECT_EQ(device_.Step(&published), hal::Status::kTimeout);
  r = Input();
  EXPECT_NE(r[kInStatus] & kStatusAdcFault, 0);
  EXPECT_NE(r[kInStatus] & kStatusStale, 0);
  EXPECT_EQ(UnpackU32(&r[kInSequence]), 3u);  // no new sample
}

/// Constant bridge outputs for the simulated ADC.
class ConstantBridges final : public hal::sim::BridgeSignalSource {
 public:
  [[nodiscard]] std::uint8_t channel_count() const override { return 6; }
  [[nodiscard]] bool Sample(double, double* mvv, double* temperature_c) override {
    for (int c = 0; c < 6; ++c) mvv[c] = 0.1 * (c + 1);
    *temperature_c = 21.0;
    return true;
  }
};

TEST_F(RegisterMapTest, SimulatedAdcFaultsReachTheStatusRegister) {
  ConstantBridges bridges;
  hal::sim::SimAdcParams params;
  params.realtime = false;
  hal::sim::SimAdc sim_adc(bridges, params);
  WrenchCore core;
  Device device(sim_adc, core);
  ASSERT_EQ(device.Start(cfg_), DeviceStatus::kOk);
  RegisterMap map(device);
  auto status = [&] {
    std::uint16_t v = 0;
    EXPECT_EQ(map.ReadInput(kInStatus, 1, &v), ModbusException::kNone);
    return v;
  };
  auto step = [&](int n) {
    hal::Status last = hal::Status::kOk;
    for (int i = 0; i < n; ++i) {
      bool published = false;
      last = device.Step(&published);
      g_now_us += 1000;
    }
    return last;
  };
  ASSERT_EQ(step(5), hal::Status::kOk);
  EXPECT_EQ(status(), kStatusSimulated);
  // No data-ready: ADC fault and stale, the wrench and sequence stay.
  std::uint16_t seq_before[2];
  ASSERT_EQ(map.ReadInput(kInSequence, 2, seq_before), ModbusException::kNone);
  sim_adc.SetFault(hal::sim::SimFault::kNoDataReady);
  EXPECT_EQ(step(3), hal::Status::kTimeout);
  EXPECT_EQ(status() & (kStatusAdcFault | kStatusStale), kStatusAdcFault | kStatusStale);
  std::uint16_t seq_after[2];
  ASSERT_EQ(map.ReadInput(kInSequence, 2, seq_after), ModbusException::kNone);
  EXPECT_EQ(UnpackU32(seq_after), UnpackU32(seq_before));
  sim_adc.SetFault(hal::sim::SimFault::kNone);
  ASSERT_EQ(step(1), hal::Status::kOk);
  EXPECT_EQ(status(), kStatusSimulated);
  // Open bridge: channel at the rail → saturated at once, bridge fault after 8 samples.
  sim_adc.SetFault(hal::sim::SimFault::kOpenBridge, 2);
  ASSERT_EQ(step(1), hal::Status::kOk);
  EXPECT_NE(status() & kStatusSaturated, 0);
  ASSERT_EQ(step(8), hal::Status::kOk);
  EXPECT_NE(status() & kStatusBridgeFault, 0);
  sim_adc.SetFault(hal::sim::SimFault::kNone);
  ASSERT_EQ(step(1), hal::Status::kOk);
  EXPECT_EQ(status(), kStatusSimulated);
  // Stuck converter: identical counts for 64 samples → ADC fault.
  sim_adc.SetFault(hal::sim::SimFault::kStuck);
  ASSERT_EQ(step(70), hal::Status::kOk);
  EXPECT_NE(status() & kStatusAdcFault, 0);
}

// ---------------------------------------------------------------------------------------------
// What the status bits say under load (issue 17): overload on the untared load, under saturation,
// with hysteresis; saturation is bit 0, not bit 2.

namespace overload_cases {
/// Counts on the Fz channel (2) that carry `fz_n` through the diagonal test calibration.
std::int32_t FzCounts(double fz_n) {
  return static_cast<std::int32_t>(std::lround(fz_n / kGain[2] / kMvvPerCount));
}
}  // namespace overload_cases

TEST_F(RegisterMapTest, OverloadIsJudgedOnTheUntaredLoad) {
  using overload_cases::FzCounts;
  StartDevice();
  adc_.counts[2] = FzCounts(380.0);  // a 380 N tool on a 400 N sensor
  Step(2);
  ASSERT_EQ(Write(kHoldCommand, {kCmdTare}), ModbusException::kNone);
  Step(6);  // the fixture's tare averages 4 samples
  auto r = Input();
  ASSERT_NE(r[kInStatus] & kStatusTareActive, 0);
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 4]), 0.0, 0.01);
  EXPECT_EQ(r[kInStatus] & kStatusOverload, 0);  // 95 % of rated
  adc_.counts[2] = FzCounts(460.0);              // 115 % of rated
  for (int i = 0; i < 20; ++i) adc_.counts[0] += (i % 2 == 0 ? 1 : -1), Step();
  r = Input();
  EXPECT_NEAR(UnpackFloat32(&r[kInWrenchFloat + 4]), 80.0, 0.01);  // the reader sees the tare
  EXPECT_NE(r[kInStatus] & kStatusOverload, 0);                    // the limit sees the body
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 1u);
  EXPECT_GE(UnpackFloat32(&r[kInPeaks + 4]), 455.0f);
  EXPECT_NEAR(UnpackFloat32(&r[kInPeaks + 4]), 460.0, 0.01);
}

TEST_F(RegisterMapTest, SaturationUnderLoadIsOverloadAndNotABridgeFault) {
  using overload_cases::FzCounts;
  StartDevice();
  // Ramp Fz from 300 N through the converter's range into saturation (its rail carries ≈ 781 N
  // through the test calibration), 10 N per sample, to 1000 N, and hold there for 50 samples.
  int saturated_samples = 0;
  for (double fz = 300.0; fz < 1000.0; fz += 10.0) {
    adc_.counts[2] = std::min(FzCounts(fz), (1 << 23) - 1);
    Step();
  }
  for (int i = 0; i < 50; ++i) {
    adc_.counts[0] += (i % 2 == 0 ? 1 : -1);  // not a stuck converter
    Step();
    const auto r = Input();
    saturated_samples += (r[kInStatus] & kStatusSaturated) != 0 ? 1 : 0;
    EXPECT_NE(r[kInStatus] & kStatusOverload, 0) << i;
    EXPECT_EQ(r[kInStatus] & kStatusBridgeFault, 0) << i;            // a load, not a broken gauge
    EXPECT_TRUE(std::isnan(UnpackFloat32(&r[kInWrenchFloat + 4])));  // no held value as true
    EXPECT_EQ(UnpackI32(&r[kInWrenchInt + 4]), 0);
  }
  EXPECT_EQ(saturated_samples, 50);
  const auto r = Input();
  EXPECT_EQ(UnpackU32(&r[kInOverloadEvents]), 1u);
  // The peak is at least what the clamped counts carry (a lower bound), far above rated.
  EXPECT_GT(UnpackFloat32(&r[kInPeaks + 4]), 770.0f);
}

TEST_F(RegisterMapTest, SaturatedFromTheStartServesNoWrenchButOverload) {
  StartDevice();
  // Started under a load beyond the converter (its rail carries ≈ 781 N through the test
  // calibration): the Fz channel reaches its rail from 90 % of it at the first samples.
  adc_.counts[2] = static_cast<std::int32_t>(0.9 * ((1 << 23) - 1));
  Step();
  adc_.counts[2] = (1 << 23) - 1;
  for (int i = 0; i < 10; ++i) adc_.counts[0] += (i % 2 == 0 ? 1 : -1), Step();
  const auto r = Input();
  EXPECT_NE(r[kInStatus] & kStatusSaturated, 0);
  EXPECT_NE(r[kInStatus] & kStatusOverload, 0);
  EXPECT_EQ(r[kInStatus] & kStatusBridgeFault, 0);
  EXPECT_TRUE(std::isnan(UnpackFloat32(&r[kInWrenchFloat + 4])));  // never 0.0 N as if measured
}

TEST_F(RegisterMapTest, HeldAt105PercentWithNoiseIsOneEvent) {
  using overload_cases::FzCounts;
  StartDevice();
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01 * 400.0);  // 1 % of rated, far above a sensor's
  int overloaded = 0;
  for (int i = 0; i < 10000; ++i) {  // 10 s at 1 kHz
    adc_.counts[2] = FzCounts(1.05 * 400.0 + noise(rng));
    Step();
    overloaded += (Input()[kInStatus] & kStatusOverload) != 0 ? 1 : 0;
  }
  EXPECT_EQ(UnpackU32(&Input()[kInOverloadEvents]), 1u);
  EXPECT_GT(overloaded, 9000);  // on from the first crossing, held by the release threshold
  // Released only at or below 100 %.
  adc_.counts[2] = FzCounts(0.99 * 400.0);
  Step(2);
  EXPECT_EQ(Input()[kInStatus] & kStatusOverload, 0);
  adc_.counts[2] = FzCounts(1.10 * 400.0);
  Step(2);
  EXPECT_EQ(UnpackU32(&Input()[kInOverloadEvents]), 2u);
}

/// Item 11: two clients write settings while the sampler runs; every acknowledged write takes
/// effect (seen in the published samples), none is lost between the sampler's two reads.
TEST_F(RegisterMapTest, ConcurrentSettingWritesAreNeverLost) {
  StartDevice();
  std::atomic<bool> stop{false};
  std::thread sampler([&] {
    while (!stop.load()) {
      bool published = false;
      adc_.counts[0] = adc_.counts[0] == 1 ? 2 : 1;  // not a stuck converter
      (void)device_.Step(&published);
    }
  });
  std::atomic<int> lost{0};
  std::thread clears([&] {  // the second client: a stream of other acknowledged writes
    for (int i = 0; i < 4000 && !stop.load(); ++i) {
      const std::uint16_t v = kCmdClearPeaks;
      if (map_->WriteHolding(kHoldCommand, &v, 1) != ModbusException::kNone) ++lost;
    }
  });
  const std::uint32_t period = device_.sample_period_us();
  for (std::uint16_t dec = 1; dec <= 300; ++dec) {
    const std::uint16_t v = static_cast<std::uint16_t>(dec % 7 + 1);
    ASSERT_EQ(map_->WriteHolding(kHoldDecimation, &v, 1), ModbusException::kNone);
    bool seen = false;
    for (int spin = 0; spin < 2000000 && !seen; ++spin) {
      DeviceSample d{};
      seen = device_.ReadLatest(&d) && d.publish_period_us == period * v;
      if (!seen) std::this_thread::yield();
    }
    if (!seen) ++lost;
  }
  stop = true;
  sampler.join();
  clears.join();
  EXPECT_EQ(lost.load(), 0);
}

}  // namespace
}  // namespace ftstack::fw
