// ftdiag diagnose --model --cal on raw converter counts: a real recording that declares no unit is
// read in the unit and converter the calibration was fitted from (the same diagnosis as with the
// declaration, against a linear model of the generator's own sensitivity); a conflicting
// declaration and values that cannot be counts are refused with one line naming file and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "tests/support/run_command.hpp"
#include "tests/tools/counts_rig.hpp"

namespace {

using namespace ftstack::test;  // NOLINT(google-build-using-namespace): the rig of these tests

/// mV/V per code of the rig's converter: ratiometric, unipolar 10 bits, gain 200.
constexpr double kMvvPerCode = 1000.0 / 200.0 / 1024.0;

CommandResult Ftdiag(const std::string& args) {
  return RunCommand(std::string(FTSTACK_BIN_DIR) + "/ftdiag diagnose " + args);
}

/// A linear sensor description with the generator's sensitivity and zero in mV/V.
void WriteModel(const std::string& path, const Eigen::Matrix<double, 8, 6>& counts_per_unit,
                const std::array<double, 8>& offset) {
  std::ofstream out(path);
  out << "{\"schema\": \"ftstack-sensor/1\", \"name\": \"printed\", \"model\": {\"type\": "
         "\"linear\", \"rated\": [40, 40, 80, 2, 2, 1.5], \"sensitivity_mvv\": [";
  for (int c = 0; c < 8; ++c) {
    out << (c > 0 ? ", [" : "[");
    for (int a = 0; a < 6; ++a) out << (a > 0 ? ", " : "") << counts_per_unit(c, a) * kMvvPerCode;
    out << "]";
  }
  out << "], \"zero_mvv\": [";
  for (std::size_t c = 0; c < 8; ++c) out << (c > 0 ? ", " : "") << offset[c] * kMvvPerCode;
  out << "]}}\n";
}

/// The output after its first line (which names the unit and its source).
std::string AfterFirstLine(const std::string& out) {
  const std::size_t nl = out.find('\n');
  return nl == std::string::npos ? "" : out.substr(nl + 1);
}

TEST(FtdiagUnits, UndeclaredCountsAreReadWithTheCalibrationsConverter) {
  Tmp tmp("ftdiag_units");
  Eigen::Matrix<double, 8, 6> counts_per_unit;
  std::array<double, 8> offset{};
  const std::vector<Row> rows = Generate(9, &counts_per_unit, &offset);
  ASSERT_TRUE(FitDeclared(tmp, rows));
  WriteModel(tmp / "sensor.json", counts_per_unit, offset);
  Write(tmp / "declared.csv", rows, true, true, 2);
  Write(tmp / "undeclared.csv", rows, false, true, 2);
  const std::string common = " --model " + (tmp / "sensor.json") + " --no-pairs --threads 1";
  const CommandResult declared =
      Ftdiag("--real " + (tmp / "declared.csv") + " --json " + (tmp / "d.json") + common);
  ASSERT_EQ(declared.exit_code, 0) << declared.out;
  EXPECT_NE(declared.out.find("[metadata]"), std::string::npos) << declared.out;
  const CommandResult undeclared =
      Ftdiag("--real " + (tmp / "undeclared.csv") + " --cal " + (tmp / "cal.json") + " --json " +
             (tmp / "u.json") + common);
  ASSERT_EQ(undeclared.exit_code, 0) << undeclared.out;
  EXPECT_NE(undeclared.out.find("real recording: bridge unit counts of converter (bits=10, "
                                "coding=unsigned, gain=200"),
            std::string::npos)
      << undeclared.out;
  EXPECT_NE(undeclared.out.find("[calibration " + (tmp / "cal.json") + "]"), std::string::npos)
      << undeclared.out;
  // The same diagnosis: the model is the generator's, so only noise and rounding remain.
  EXPECT_GT(AfterFirstLine(declared.out).size(), 20u) << declared.out;
  EXPECT_EQ(AfterFirstLine(undeclared.out), AfterFirstLine(declared.out));
  // Without the calibration nothing says counts: the codes lie outside the assumed mV/V range.
  const CommandResult bare =
      Ftdiag("--real " + (tmp / "undeclared.csv") + " --json " + (tmp / "b.json") + common);
  EXPECT_EQ(bare.exit_code, 2) << bare.out;
  EXPECT_NE(bare.out.find("declare the unit"), std::string::npos) << bare.out;
}

TEST(FtdiagUnits, AConflictingDeclarationOrValuesThatAreNoCountsAreRefused) {
  Tmp tmp("ftdiag_units_refused");
  Eigen::Matrix<double, 8, 6> counts_per_unit;
  std::array<double, 8> offset{};
  ASSERT_TRUE(FitDeclared(tmp, Generate(9, &counts_per_unit, &offset)));
  WriteModel(tmp / "sensor.json", counts_per_unit, offset);
  const std::string header = "t,Fx,Fy,Fz,Mx,My,Mz,b0,b1,b2,b3,b4,b5,b6,b7\n";
  const std::string body = header + "0,0,0,0,0,0,0,500,500,500,500,500,500,500,500\n";
  auto refused = [&](const std::string& name, const std::string& text, const std::string& opts) {
    std::ofstream(tmp / name) << text;
    const CommandResult r =
        Ftdiag("--model " + (tmp / "sensor.json") + " --real " + (tmp / name) + " --cal " +
               (tmp / "cal.json") + " --json " + (tmp / "r.json") + opts);
    EXPECT_EQ(r.exit_code, 2) << name << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(r.out.rfind("ftdiag: ", 0), 0u) << r.out;
    return r.out;
  };
  std::string err = refused(
      "twelve.csv", "# sensor: x\n# converter: bits=12, coding=unsigned, gain=200\n" + body, "");
  EXPECT_NE(err.find("twelve.csv:2: declares bridge unit counts of converter (bits=12"),
            std::string::npos)
      << err;
  err = refused("mvv.csv", "# bridge_unit: mV/V\n" + body, "");
  EXPECT_NE(err.find("mvv.csv:1: declares bridge unit mV/V"), std::string::npos) << err;
  err = refused("plain.csv", body, " --converter bits=10,coding=offset-binary,gain=200");
  EXPECT_NE(err.find("--bridge-unit/--converter: declares bridge unit counts"), std::string::npos)
      << err;
  err = refused("half.csv", header + "0,0,0,0,0,0,0,500,500,500.5,500,500,500,500,500\n", "");
  EXPECT_NE(err.find("half.csv:2:23: b2 = 500.5 is not a whole code"), std::string::npos) << err;
  err = refused("high.csv", header + "0,0,0,0,0,0,0,500,500,1024,500,500,500,500,500\n", "");
  EXPECT_NE(err.find("high.csv:2:23: b2 = 1024 lies outside"), std::string::npos) << err;
}

}  // namespace
