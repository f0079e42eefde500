// A calibration that flags an axis invalid (its rig never loaded it), served by the real ftd over
// Modbus: that axis never reads as a value — NaN / 0 and status bit 10 — in the sensor frame and
// in every tool-frame axis the transform mixes it into; the other axes stay measurements
// (issue 17, item 16).
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "calibration/file/cal_file.hpp"
#include "firmware/register_map.hpp"
#include "firmware/status_bits.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/sensor_description.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/builtin_adc.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/modbus_tcp_client.hpp"

namespace ftstack {
namespace {

using fw::UnpackFloat32;
using fw::UnpackI32;
using fw::UnpackU32;

constexpr int kRegs = 77;  // input registers 0 … 76

class Client : public test::ModbusTcpClient {
 public:
  using ModbusTcpClient::ModbusTcpClient;
  bool Input(std::array<std::uint16_t, kRegs>* r) {
    return modbus_read_input_registers(ctx(), 0, kRegs, r->data()) == kRegs;
  }
  bool WriteFloat(int addr, float v) {
    std::uint16_t w[2];
    fw::PackFloat32(v, w);
    return modbus_write_registers(ctx(), addr, 2, w) == 2;
  }
  bool Write(int addr, std::uint16_t v) { return modbus_write_register(ctx(), addr, v) == 1; }
  /// Reads until the sequence has moved by `n` (a sample published after the last change).
  bool After(std::uint32_t n, std::array<std::uint16_t, kRegs>* r) {
    if (!Input(r)) return false;
    const std::uint32_t start = UnpackU32(&(*r)[fw::kInSequence]);
    for (int i = 0; i < 500; ++i) {
      if (!Input(r)) return false;
      if (UnpackU32(&(*r)[fw::kInSequence]) - start >= n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
};

float F(const std::array<std::uint16_t, kRegs>& r, int base, int axis) {
  return UnpackFloat32(&r[static_cast<std::size_t>(base + 2 * axis)]);
}

TEST(FtdInvalidAxis, AFlaggedAxisIsNeverServedAsAValue) {
  const test::TempDir tmp("ftd_axis");
  const std::string path = tmp / "no_mz.json";
  {
    const test::BuiltinAdc builtin = test::BuiltinSimAdc();
    const sim::SensorDescription desc = sim::DefaultSensorDescription();
    cal::CalFile f = sim::IdealCalibration(*desc.model, builtin.info);
    f.cal.invalid_axes = 1u << 5;  // Mz
    cal::SaveCalFile(path, f);
  }
  // Mz = 2 N·m is applied: the sensor sees it, but this calibration cannot tell it.
  test::FtdProcess ftd(
      {"--sim-wrench", "10,-20,100,0.5,-0.3,2", "--cal", path, "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  EXPECT_NE(ftd.Stderr().find("flags axis Mz invalid"), std::string::npos) << ftd.Stderr();
  Client c(ftd.port());
  ASSERT_TRUE(c.connected());
  std::array<std::uint16_t, kRegs> r{};
  ASSERT_TRUE(c.After(50, &r));
  EXPECT_NE(r[fw::kInStatus] & fw::kStatusAxisInvalid, 0);
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusCalInvalid, 0);  // the file itself is good
  EXPECT_TRUE(std::isnan(F(r, fw::kInWrenchFloat, 5)));
  EXPECT_EQ(UnpackI32(&r[fw::kInWrenchInt + 10]), 0);
  EXPECT_TRUE(std::isnan(F(r, fw::kInPeaks, 5)));
  const std::array<double, 5> applied = {10, -20, 100, 0.5, -0.3};
  for (int a = 0; a < 5; ++a) {
    const double tol = a < 3 ? 0.5 : 0.02;  // ≫ noise (1e-4 of rated), ≪ the loads
    EXPECT_NEAR(F(r, fw::kInWrenchFloat, a), applied[static_cast<std::size_t>(a)], tol) << a;
    EXPECT_NEAR(UnpackI32(&r[static_cast<std::size_t>(fw::kInWrenchInt + 2 * a)]) * 1e-3,
                applied[static_cast<std::size_t>(a)], tol)
        << a;
  }
  // A tool frame turned 90° about x: the tool's My is the sensor's −Mz (unknown), its Mz the
  // sensor's My; forces have no moment part (no offset). My must read NaN, Mz a value.
  ASSERT_TRUE(c.Write(fw::kHoldUnlock, 42435));
  ASSERT_TRUE(c.WriteFloat(16, 90.0f));  // tool_rx_deg
  ASSERT_TRUE(c.After(50, &r));
  EXPECT_NE(r[fw::kInStatus] & fw::kStatusAxisInvalid, 0);
  EXPECT_TRUE(std::isnan(F(r, fw::kInWrenchFloat, 4))) << F(r, fw::kInWrenchFloat, 4);
  EXPECT_EQ(UnpackI32(&r[fw::kInWrenchInt + 8]), 0);
  EXPECT_FALSE(std::isnan(F(r, fw::kInWrenchFloat, 5)));
  EXPECT_NEAR(std::fabs(F(r, fw::kInWrenchFloat, 5)), 0.3, 0.02);  // the sensor's My, turned
  EXPECT_NEAR(std::fabs(F(r, fw::kInWrenchFloat, 3)), 0.5, 0.02);  // Mx stays Mx
  EXPECT_NEAR(F(r, fw::kInWrenchFloat, 0), 10.0, 0.5);
  EXPECT_EQ(ftd.Stop(), 0);
}

}  // namespace
}  // namespace ftstack
