// ATI DAQ .cal import: v1.0 against hand-derived transforms, v1.0 vs v1.1 consistency, published
// files carrying both kinds of rows, units, rotation, malformed files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include "calibration/fit/apply.hpp"
#include "calibration/fit/ati.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::cal {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The Axis rows of a v1.0 file read by a regular expression (independent of the importer).
struct RawAxis {
  std::array<std::array<double, 6>, 6> values{};
  std::array<double, 6> scale{};
  std::array<double, 6> max{};
};
RawAxis ReadAxisRows(const std::string& text) {
  RawAxis raw;
  const std::regex re(
      R"re(<Axis\s+Name="(\w+)"\s+values="([^"]*)"\s+max="([^"]*)"\s+scale="([^"]*)")re");
  const char* names[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  int found = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it) {
    int a = 0;
    while (a < 6 && (*it)[1] != names[a]) ++a;
    std::istringstream vs((*it)[2].str());
    for (double& v : raw.values[static_cast<std::size_t>(a)]) vs >> v;
    raw.max[static_cast<std::size_t>(a)] = std::stod((*it)[3].str());
    raw.scale[static_cast<std::size_t>(a)] = std::stod((*it)[4].str());
    ++found;
  }
  EXPECT_EQ(found, 6);
  return raw;
}

/// ATI's BasicTransform for a pure displacement along z, written out by hand:
/// Mx' = Mx + dz·Fy, My' = My − dz·Fx (moment about the point moved by +dz), forces unchanged.
Eigen::MatrixXd HandTransformDz(const RawAxis& raw, double dz) {
  Eigen::MatrixXd m(6, 6);
  for (int a = 0; a < 6; ++a) {
    for (int c = 0; c < 6; ++c) {
      m(a, c) = raw.values[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)] /
                raw.scale[static_cast<std::size_t>(a)];
    }
  }
  m.row(3) += dz * m.row(1);
  m.row(4) -= dz * m.row(0);
  return m;
}

Eigen::MatrixXd Matrix(const CalFile& f) {
  Eigen::MatrixXd m(6, f.cal.channel_count);
  for (int a = 0; a < 6; ++a) {
    for (int c = 0; c < f.cal.channel_count; ++c) {
      m(a, c) = f.cal.matrix[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)];
    }
  }
  return m;
}

TEST(AtiImport, Version10AxisRowsScaledAndTransformedLikeAtisLibrary) {
  const std::string path = test::TestDataPath("ati/FT11712.cal");
  const AtiImport imp = ImportAtiCal(path);
  EXPECT_EQ(imp.version, "1.0");
  EXPECT_FALSE(imp.used_user_axis);
  EXPECT_EQ(imp.file.serial, "FT11712");
  EXPECT_EQ(imp.file.input_unit, "V");
  const RawAxis raw = ReadAxisRows(ReadText(path));
  const Eigen::MatrixXd expect = HandTransformDz(raw, 0.0120142);  // N, N-m, m in the file
  const Eigen::MatrixXd got = Matrix(imp.file);
  EXPECT_LT((got - expect).cwiseAbs().maxCoeff(), 1e-12 * expect.cwiseAbs().maxCoeff());
  const std::array<double, 6> rated = {65, 65, 200, 5, 5, 5};
  for (std::size_t a = 0; a < 6; ++a) EXPECT_DOUBLE_EQ(imp.file.rated[a], rated[a]);
  // The file saves and verifies through our own format and fixed-point loader.
  const test::TempDir tmp("ati");
  SaveCalFile(tmp / "ft11712.json", imp.file);
  const CalFile back = LoadCalFile(tmp / "ft11712.json");
  EXPECT_LT((Matrix(back) - got).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(AtiImport, Version11WrittenFromVersion10NumbersAgrees) {
  // Write a v1.1 file whose UserAxis rows are derived here (by hand, 5 decimals as ATI prints
  // them) from the v1.0 Axis numbers; importing it must give the same calibration.
  const std::string v10 = test::TestDataPath("ati/FT11712.cal");
  const RawAxis raw = ReadAxisRows(ReadText(v10));
  const Eigen::MatrixXd user = HandTransformDz(raw, 0.0120142);
  const char* names[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  std::ostringstream f;
  f << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    << "<FTSensor Serial=\"FT11712\" BodyStyle=\"Gamma\" Family=\"DAQ\" NumGages=\"6\" "
       "CalFileVersion=\"1.1\">\n"
    << "  <Calibration PartNumber=\"SI-65-5\" CalDate=\"11/29/2011\" ForceUnits=\"N\" "
       "TorqueUnits=\"N-m\" DistUnits=\"m\" OutputRange=\"20\" OutputBipolar=\"True\">\n";
  for (int a = 0; a < 6; ++a) {
    f << "    <UserAxis Name=\"" << names[a] << "\" values=\"";
    for (int c = 0; c < 6; ++c) {
      char buf[32];
      std::snprintf(buf, sizeof buf, " %.5f", user(a, c));
      f << buf;
    }
    f << " \" max=\"" << raw.max[static_cast<std::size_t>(a)] << "\"/>\n";
  }
  f << "  </Calibration>\n</FTSensor>\n";
  const AtiImport a11 = ParseAtiCal(f.str(), "derived-v1.1.cal");
  const AtiImport a10 = ImportAtiCal(v10);
  EXPECT_TRUE(a11.used_user_axis);
  EXPECT_TRUE(a11.warnings.empty());
  const Eigen::MatrixXd d = Matrix(a11.file) - Matrix(a10.file);
  EXPECT_LE(d.cwiseAbs().maxCoeff(), 0.5e-5 * 1.0001);  // the 5-decimal rounding, N/V and N·m/V
  for (std::size_t a = 0; a < 6; ++a) EXPECT_DOUBLE_EQ(a11.file.rated[a], a10.file.rated[a]);
  // Same wrench for any gauge voltages within ±10 V, up to the rounding carried through.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int k = 0; k < 100; ++k) {
    Eigen::VectorXd v(6);
    for (int c = 0; c < 6; ++c) v(c) = u(rng);
    const Eigen::VectorXd w = d * v;
    EXPECT_LE(w.cwiseAbs().maxCoeff(), 6 * 0.5e-5 * 10 * 1.0001);
  }
}

// Published ATI calibrations carrying both Axis and UserAxis rows (the UserAxis rows are ATI's
// own result): a Gamma SI-130-10 (N, N-m, m) and a Nano17 FT8577 (N, N-mm, mm).
const char* kGamma = R"(<?xml version="1.0" encoding="utf-8"?>
<FTSensor Serial="GAMMA-PUBLISHED" BodyStyle="Gamma" Family="DAQ" NumGages="6" CalFileVersion="1.1">
	<Calibration PartNumber="SI-130-10" CalDate="1/1/2014" ForceUnits="N" TorqueUnits="N-m" DistUnits="m" OutputMode="Ground Referenced Differential" OutputRange="20" HWTempComp="True" GainMultiplier="1" CableLossDetection="False" OutputBipolar="True">
		<Axis Name="Fx" values=" -0.27053  -0.14278   0.35224 -32.30108  -0.22111  32.83006 " max="130" scale="2.33993181642138"/>
		<Axis Name="Fy" values="  0.21616  37.46357   0.05722 -18.83819   0.35126 -18.85998 " max="130" scale="2.33993181642138"/>
		<Axis Name="Fz" values=" 18.48980  -0.25078  18.75502  -0.41293  18.60017  -0.58878 " max="400" scale="0.747981765296576"/>
		<Axis Name="Tx" values="  0.05325   0.15667 -32.28492   0.82744  32.26505  -1.25235 " max="10" scale="44.8196831994584"/>
		<Axis Name="Ty" values=" 37.31421  -0.62445 -18.43472   0.63319 -18.48677   0.60638 " max="10" scale="44.8196831994584"/>
		<Axis Name="Tz" values=" -0.13536 -18.46474   0.04406 -18.57097   0.27123 -18.80438 " max="10" scale="43.1398206760749"/>
		<BasicTransform Dx="0" Dy="0" Dz="0.0120142" Rx="0" Ry="0" Rz="0"/>
		<UserAxis Name="Fx" values=" -0.11562  -0.06102   0.15054 -13.80428  -0.09449  14.03035 " max="130"/>
		<UserAxis Name="Fy" values="  0.09238  16.01054   0.02446  -8.05074   0.15012  -8.06005 " max="130"/>
		<UserAxis Name="Fz" values=" 24.71959  -0.33527  25.07417  -0.55206  24.86714  -0.78715 " max="400"/>
		<UserAxis Name="Tx" values="  0.00230   0.19585  -0.72004  -0.07826   0.72169  -0.12478 " max="10"/>
		<UserAxis Name="Ty" values="  0.83393  -0.01320  -0.41312   0.17997  -0.41133  -0.15503 " max="10"/>
		<UserAxis Name="Tz" values=" -0.00314  -0.42802   0.00102  -0.43048   0.00629  -0.43589 " max="10"/>
	</Calibration>
</FTSensor>
)";

const char* kNano17 = R"(<?xml version="1.0" encoding="utf-8"?>
<FTSensor Serial="FT8577" BodyStyle="Nano17" Family="DAQ" NumGages="6" CalFileVersion="1.1">
	<Calibration PartNumber="SI-25-0.25" CalDate="3/5/2014" ForceUnits="N" TorqueUnits="N-mm" DistUnits="mm" OutputMode="Ground Referenced Differential" OutputRange="20" HWTempComp="True" GainMultiplier="1" CableLossDetection="False" OutputBipolar="True">
		<Axis Name="Fx" values=" -0.06744  -0.06253   0.34834  37.34247   1.90538 -37.39899 " max="25" scale="11.3650042049178"/>
		<Axis Name="Fy" values="  0.55821 -45.57953  -0.51071  22.00831  -0.39426  21.28868 " max="25" scale="11.3650042049178"/>
		<Axis Name="Fz" values=" 22.07572   0.66524  22.64229   0.15088  21.81132  -0.64550 " max="35" scale="5.89341666193018"/>
		<Axis Name="Tx" values="  0.25495   0.07335  38.61586   0.30585 -38.71584   1.08341 " max="250" scale="1.82292883446332"/>
		<Axis Name="Ty" values="-43.12768  -1.34402  23.17737   0.13073  21.67933  -0.58572 " max="250" scale="1.82292883446332"/>
		<Axis Name="Tz" values="  0.23141 -23.28809  -0.53681 -22.47927   1.56779 -22.44391 " max="250" scale="1.57420173377595"/>
		<BasicTransform Dx="0" Dy="0" Dz="6.096" Rx="0" Ry="0" Rz="0"/>
		<UserAxis Name="Fx" values=" -0.00593  -0.00550   0.03065   3.28574   0.16765  -3.29072 " max="25"/>
		<UserAxis Name="Fy" values="  0.04912  -4.01052  -0.04494   1.93650  -0.03469   1.87318 " max="25"/>
		<UserAxis Name="Fz" values="  3.74583   0.11288   3.84196   0.02560   3.70096  -0.10953 " max="35"/>
		<UserAxis Name="Tx" values="  0.43927 -24.40787  20.90948  11.97267 -21.44973  12.01322 " max="250"/>
		<UserAxis Name="Ty" values="-23.62228  -0.70375  12.52751 -19.95816  10.87057  19.73889 " max="250"/>
		<UserAxis Name="Tz" values="  0.14700 -14.79358  -0.34100 -14.27979   0.99593 -14.25733 " max="250"/>
	</Calibration>
</FTSensor>
)";

TEST(AtiImport, PublishedFilesWithBothRowKindsAgreeWithoutWarning) {
  for (const char* text : {kGamma, kNano17}) {
    const AtiImport imp = ParseAtiCal(text, "published.cal");
    EXPECT_TRUE(imp.used_user_axis);
    EXPECT_TRUE(imp.warnings.empty()) << imp.warnings.front();
    ASSERT_EQ(imp.from_axis.rows(), 6);
    ASSERT_EQ(imp.from_user_axis.rows(), 6);
  }
  // Units: the Nano17's torque rows come in N-mm per V and become N·m per V; rated 250 N-mm.
  const AtiImport nano = ParseAtiCal(kNano17, "nano17.cal");
  EXPECT_NEAR(nano.file.cal.matrix[3][1], -24.40787e-3, 1e-12);
  EXPECT_NEAR(nano.file.rated[3], 0.25, 1e-15);
  EXPECT_NEAR(nano.file.cal.matrix[0][3], 3.28574, 1e-12);
}

TEST(AtiImport, DisagreeingRowsAreReported) {
  std::string text = kGamma;
  const std::string from = "0.83393  -0.01320";
  text.replace(text.find(from), from.size(), "0.83493  -0.01320");  // Ty, gauge 0: +1e-3
  const AtiImport imp = ParseAtiCal(text, "edited.cal");
  ASSERT_EQ(imp.warnings.size(), 1u);
  EXPECT_NE(imp.warnings[0].find("Ty row"), std::string::npos) << imp.warnings[0];
  EXPECT_NEAR(imp.file.cal.matrix[4][0], 0.83493, 1e-12);  // UserAxis is used, as ATI says
}

std::string IdentityFile(const std::string& units, const std::string& transform) {
  std::ostringstream f;
  f << "<FTSensor Serial=\"X\" NumGages=\"6\" CalFileVersion=\"1.0\"><Calibration " << units
    << " OutputRange=\"20\">\n";
  const char* names[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  for (int a = 0; a < 6; ++a) {
    f << "<Axis Name=\"" << names[a] << "\" values=\"";
    for (int c = 0; c < 6; ++c) f << (a == c ? " 2" : " 0");
    f << "\" max=\"10\" scale=\"2\"/>\n";
  }
  f << transform << "\n</Calibration></FTSensor>\n";
  return f.str();
}

TEST(AtiImport, ImperialUnitsAndInchDisplacementConvertToSi) {
  const AtiImport imp =
      ParseAtiCal(IdentityFile("ForceUnits=\"lbf\" TorqueUnits=\"lbf-in\" DistUnits=\"in\"",
                               "<BasicTransform Dz=\"1\"/>"),
                  "imperial.cal");
  const double lbf = 4.4482216152605;  // N (exact definition)
  const double lbf_in = lbf * 0.0254;  // N·m
  EXPECT_NEAR(imp.file.cal.matrix[0][0], lbf, 1e-12);
  EXPECT_NEAR(imp.file.cal.matrix[3][3], lbf_in, 1e-12);
  // Mx' = Mx + dz·Fy with dz = 1 in = 0.0254 m and Fy = 1 lbf/V on gauge 1.
  EXPECT_NEAR(imp.file.cal.matrix[3][1], 0.0254 * lbf, 1e-12);
  EXPECT_NEAR(imp.file.cal.matrix[4][0], -0.0254 * lbf, 1e-12);
  EXPECT_NEAR(imp.file.rated[0], 10 * lbf, 1e-9);
  EXPECT_NEAR(imp.file.rated[5], 10 * lbf_in, 1e-9);
}

TEST(AtiImport, RotationAboutZByNinetyDegrees) {
  // ATI's rotation matrix for Rz = 90°: R[0][1] = 1, R[1][0] = −1, R[2][2] = 1 → Fx' = Fy,
  // Fy' = −Fx, Tx' = Ty, Ty' = −Tx.
  const AtiImport imp =
      ParseAtiCal(IdentityFile("ForceUnits=\"N\" TorqueUnits=\"N-m\" DistUnits=\"m\"",
                               "<BasicTransform Rz=\"90\"/>"),
                  "rot.cal");
  Eigen::MatrixXd expect = Eigen::MatrixXd::Zero(6, 6);
  expect(0, 1) = 1;
  expect(1, 0) = -1;
  expect(2, 2) = 1;
  expect(3, 4) = 1;
  expect(4, 3) = -1;
  expect(5, 5) = 1;
  EXPECT_LT((Matrix(imp.file) - expect).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(AtiImport, MalformedFilesAreRefusedWithPosition) {
  const std::string good = kGamma;
  auto refused = [](const std::string& text, const std::string& want) {
    try {
      (void)ParseAtiCal(text, "bad.cal");
    } catch (const CalFileError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("bad.cal:", 0), 0u) << e.what();
      return;
    }
    ADD_FAILURE() << "accepted: " << want;
  };
  refused(good.substr(0, good.size() / 2), "truncated");
  refused(good.substr(0, good.size() - 15), "truncated");
  std::string nan = good;
  nan.replace(nan.find("-0.27053"), 8, "nan     ");
  refused(nan, "not a finite number");
  std::string few = good;
  few.replace(few.find(" 32.83006 \" max=\"130\" scale"), 10, " ");
  refused(few, "5 values, NumGages says 6");
  std::string unit = good;
  unit.replace(unit.find("\"N-m\""), 5, "\"N-x\"");
  refused(unit, "unknown TorqueUnits");
  refused("hello", "no XML elements");
  // Found by fuzzing (fuzz/corpus/ati/regression_unclosed_value): a quote swallowed by a
  // malformed attribute name left the next value open; the scanner restarted at 0 forever.
  refused(ReadText(test::TestDataPath("regression/ati_unclosed_value.cal")), "value is not closed");
  // Found by fuzzing (fuzz/corpus/ati/regression_numgages_beyond_int, 2026-11-25): a NumGages
  // beyond int reached the conversion to int (undefined behaviour) before its range check.
  for (const char* big : {"3333333333333333333333333333333333333336", "1e300", "-5e9", "8.9e0"}) {
    std::string gages = good;
    gages.replace(gages.find("NumGages=\"6\""), 12, std::string("NumGages=\"") + big + "\"");
    if (std::string(big) == "8.9e0") {  // the count truncates, as it always did: 8 is in range
      refused(gages, "values, NumGages says 8");
    } else {
      refused(gages, std::string("NumGages ") + big + " outside 1..8");
    }
  }
}

TEST(AtiImport, AppliedToVoltsThroughTheFixedPointCore) {
  const AtiImport imp = ImportAtiCal(test::TestDataPath("ati/FT11712.cal"));
  Recording rec;
  rec.names = {"t", "b0", "b1", "b2", "b3", "b4", "b5"};
  rec.columns = {{0.0}, {0.1}, {-0.2}, {0.3}, {1.5}, {-0.7}, {0.25}};
  const Recording out = ApplyCalibration(imp.file, rec);
  const Eigen::MatrixXd m = Matrix(imp.file);
  // 16-bit counts over ±10 V: the input is quantised to 10/32767 V before the matrix.
  const double q = 10.0 / 32767.0;
  for (int a = 0; a < 6; ++a) {
    double expect = 0;
    for (int c = 0; c < 6; ++c) {
      expect += m(a, c) * std::round(rec.columns[static_cast<std::size_t>(c + 1)][0] / q) * q;
    }
    EXPECT_NEAR(out.Column(WrenchColumns()[static_cast<std::size_t>(a)])[0], expect,
                a < 3 ? 1e-3 : 1e-5);
  }
}

}  // namespace
}  // namespace ftstack::cal
