// ftcal check's core on an independently written generator: a known tool in 8 random robot
// poses, a sensor whose true response differs from its calibration by a 1 % gain on one axis or
// a 0.5° frame rotation; bridges made by inverting the calibration matrix, read back through the
// fixed-point core.
#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/check.hpp"
#include "calibration/fit/commands.hpp"
#include "calibration/fit/input_units.hpp"
#include "measurement/recording.hpp"
#include "tests/calibration/run_ftcal.hpp"

namespace {

using ftstack::Recording;
using ftstack::cal::CalFile;
using ftstack::cal::CheckCalibration;
using ftstack::cal::CheckPosesFromRecording;
using ftstack::cal::CheckResult;
using ftstack::cal::CheckTool;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// A 6-bridge linear calibration: wrench = C·(b − offset) + bias, C about 60 N per mV/V (a 5 kg
/// tool stays well inside the ±3.9 mV/V converter).
CalFile MakeCal(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  CalFile f;
  f.cal.channel_count = 6;
  Mat6 c = Mat6::Identity() * 60.0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) c(i, j) += 4.0 * uni(rng);
  c.bottomRows<3>() *= 0.05;  // N·m per mV/V
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j)
      f.cal.matrix[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = c(i, j);
    f.cal.offset_mvv[static_cast<std::size_t>(i)] = 0.2 * uni(rng);
    f.cal.bias[static_cast<std::size_t>(i)] = 0.0;
  }
  f.adc = ftstack::cal::DefaultAdc(6);
  f.rated = {100, 100, 100, 5, 5, 5};
  f.uncertainty = {0.02, 0.02, 0.02, 0.002, 0.002, 0.002};
  return f;
}

/// How the true sensor differs from the calibration: reading = T · wrench.
struct Fault {
  int gain_axis = -1;
  double gain = 0.0;
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();
};

Mat6 FaultMatrix(const Fault& f) {
  Mat6 t = Mat6::Identity();
  if (f.gain_axis >= 0) t(f.gain_axis, f.gain_axis) += f.gain;
  if (f.rotation_rad.norm() > 0) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(f.rotation_rad.norm(), f.rotation_rad.normalized()).toRotationMatrix();
    t.topLeftCorner<3, 3>() = r;
    t.bottomRightCorner<3, 3>() = r;
  }
  return t;
}

/// 8 random orientations, 20 rows each; bridges from the inverse calibration of T·w + bias +
/// noise (5 mN, 0.3 mN·m per row).
Recording Generate(const CalFile& cal, const CheckTool& tool, const Fault& fault, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Mat6 c;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      c(i, j) = cal.cal.matrix[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  const Mat6 c_inv = c.inverse();
  const Mat6 t = FaultMatrix(fault);
  Vec6 bias;
  bias << 0.3, -0.2, 0.5, 0.01, -0.02, 0.005;  // the sensor's zero has drifted
  Recording rec;
  rec.path = "generated";
  rec.names = {"t", "pose", "gx_mps2", "gy_mps2", "gz_mps2", "b0", "b1", "b2", "b3", "b4", "b5"};
  rec.columns.resize(rec.names.size());
  for (int p = 0; p < 8; ++p) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Vector3d g = q.toRotationMatrix().transpose() * Eigen::Vector3d(0, 0, -9.80665);
    Vec6 w;
    w.head<3>() = tool.mass_kg * g;
    w.tail<3>() = tool.com_m.cross(tool.mass_kg * g);
    for (int k = 0; k < 20; ++k) {
      Vec6 reading = t * w + bias;
      for (int a = 0; a < 6; ++a) reading(a) += (a < 3 ? 5e-3 : 3e-4) * gauss(rng);
      const Vec6 b = c_inv * reading;
      rec.columns[0].push_back(p * 20 + k);
      rec.columns[1].push_back(p);
      for (int i = 0; i < 3; ++i) rec.columns[static_cast<std::size_t>(2 + i)].push_back(g(i));
      for (int i = 0; i < 6; ++i)
        rec.columns[static_cast<std::size_t>(5 + i)].push_back(
            b(i) + cal.cal.offset_mvv[static_cast<std::size_t>(i)]);
    }
  }
  return rec;
}

CheckResult RunCheckOn(const CalFile& cal, const CheckTool& tool, const Fault& fault,
                       unsigned seed) {
  const Recording rec = Generate(cal, tool, fault, seed);
  return CheckCalibration(CheckPosesFromRecording(cal, rec), tool, cal.uncertainty);
}

const double kMasses[] = {1.0, 2.5, 5.0};

CheckTool Tool(double mass) {
  CheckTool tool;
  tool.mass_kg = mass;
  tool.com_m = {0.012, -0.018, 0.085};
  return tool;
}

TEST(CalCheck, PassesACorrectCalibration) {
  std::mt19937_64 rng(3);
  const CalFile cal = MakeCal(rng);
  for (const double m : kMasses) {
    for (unsigned seed = 1; seed <= 10; ++seed) {
      const CheckResult r = RunCheckOn(cal, Tool(m), {}, seed);
      EXPECT_TRUE(r.pass) << m << " kg, seed " << seed << ": " << r.verdict;
      for (const auto& ax : r.axes) {
        if (ax.gain_excited) {
          EXPECT_LT(std::fabs(ax.gain_error), 1e-3);  // a tenth of the fault
        }
      }
    }
  }
}

TEST(CalCheck, DetectsAOnePercentGainErrorOnOneAxis) {
  std::mt19937_64 rng(4);
  const CalFile cal = MakeCal(rng);
  for (const double m : kMasses) {
    for (const int axis : {0, 2, 3}) {
      for (unsigned seed = 1; seed <= 5; ++seed) {
        const CheckResult r = RunCheckOn(cal, Tool(m), {axis, 0.01, Eigen::Vector3d::Zero()}, seed);
        EXPECT_FALSE(r.pass) << m << " kg, axis " << axis << ", seed " << seed;
        const auto& ax = r.axes[static_cast<std::size_t>(axis)];
        EXPECT_FALSE(ax.pass) << r.verdict;
        ASSERT_TRUE(ax.gain_excited);
        EXPECT_NEAR(ax.gain_error, 0.01, 1e-3) << m << " kg axis " << axis;
        EXPECT_GT(ax.gain_error - 3.0 * ax.gain_sigma, 0.0) << "significant: " << r.verdict;
        for (int a = 0; a < 3; ++a) {
          if (a != axis) {
            EXPECT_TRUE(r.axes[static_cast<std::size_t>(a)].pass) << r.verdict;
          }
        }
      }
    }
  }
}

TEST(CalCheck, DetectsAHalfDegreeFrameRotation) {
  std::mt19937_64 rng(5);
  const CalFile cal = MakeCal(rng);
  for (const double m : kMasses) {
    for (int about = 0; about < 3; ++about) {
      for (unsigned seed = 1; seed <= 5; ++seed) {
        Fault f;
        f.rotation_rad(about) = 0.5 * kDeg;
        const CheckResult r = RunCheckOn(cal, Tool(m), f, seed);
        EXPECT_FALSE(r.pass) << m << " kg, about " << about << ", seed " << seed;
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(r.rotation_rad(i), f.rotation_rad(i), 0.05 * kDeg)
              << m << " kg, about " << about << ", component " << i;
        }
      }
    }
  }
}

TEST(CalCheck, RefusesTooFewOrFlatPoses) {
  std::mt19937_64 rng(6);
  const CalFile cal = MakeCal(rng);
  std::vector<ftstack::cal::CheckPose> poses(5);
  EXPECT_THROW((void)CheckCalibration(poses, Tool(1.0), cal.uncertainty), std::invalid_argument);
  poses.resize(8);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    poses[i].gravity_mps2 = {std::cos(0.3 * static_cast<double>(i)) * 9.8,
                             std::sin(0.3 * static_cast<double>(i)) * 9.8, 0.0};  // one plane
  }
  EXPECT_THROW((void)CheckCalibration(poses, Tool(1.0), cal.uncertainty), std::invalid_argument);
}

TEST(CalCheck, CommandLineGivesAVerdictAndAnExitCodeAScriptCanUse) {
  std::mt19937_64 rng(7);
  const CalFile cal = MakeCal(rng);
  const auto dir =
      std::filesystem::temp_directory_path() / ("ftcal_check_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string cal_path = (dir / "cal.json").string();
  ftstack::cal::SaveCalFile(cal_path, cal);
  const std::string tool = " --mass-kg 2.5 --com-m 0.012,-0.018,0.085";
  struct Case {
    Fault fault;
    int code;
    std::string word;
  };
  const Case cases[] = {{{}, 0, "PASS"}, {{1, 0.01, Eigen::Vector3d::Zero()}, 4, "FAIL: Fy"}};
  for (const Case& c : cases) {
    const std::string in = (dir / "poses.csv").string();
    ftstack::WriteRecording(in, Generate(cal, Tool(2.5), c.fault, 11));
    std::string out;
    EXPECT_EQ(ftstack::test::RunFtcal("check --cal " + cal_path + " --in " + in + tool, &out),
              c.code)
        << out;
    std::printf("%s", out.c_str());  // for the record (docs/robot.md)
    EXPECT_NE(out.find(c.word), std::string::npos) << out;
    EXPECT_NE(out.find("gain error"), std::string::npos) << out;
  }
  // The Fy fault (1 % of 24.5 N) is no longer beyond 3 σ when the tool or the poses are stated
  // this loosely: the mass to 0.5 kg (4.9 N on every force), the pose angles to 5° (2.1 N per
  // pose); a centre of mass known only to 0.1 m widens the moments, not the forces' σ.
  for (const std::string loose : {" --mass-sigma-kg 0.5", " --pose-angle-sigma-deg 5"}) {
    std::string text;
    EXPECT_EQ(ftstack::test::RunFtcal("check --cal " + cal_path + " --in " +
                                          (dir / "poses.csv").string() + tool + loose,
                                      &text),
              0)
        << loose << "\n"
        << text;
  }
  {
    std::string text;
    EXPECT_EQ(
        ftstack::test::RunFtcal("check --cal " + cal_path + " --in " +
                                    (dir / "poses.csv").string() + tool + " --com-sigma-m 0.1",
                                &text),
        4)
        << text;  // the forces still see the fault
    EXPECT_NE(text.find("FAIL: Fy"), std::string::npos) << text;
  }
  // No tool given: one line, exit 1.
  std::string out;
  EXPECT_EQ(ftstack::test::RunFtcal(
                "check --cal " + cal_path + " --in " + (dir / "poses.csv").string(), &out),
            1);
  EXPECT_NE(out.find("needs the tool"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

// A calibration fitted from raw counts of a 24-bit converter: a pose recording of the same counts
// without a unit declaration is read with the calibration's converter (the same report as when
// declaring it), and a recording declaring another unit is refused with one line.
TEST(CalCheck, UndeclaredCountsUseTheCalibrationsConverterAndAnotherDeclarationIsRefused) {
  std::mt19937_64 rng(3);
  CalFile cal = MakeCal(rng);
  const std::string conv = "bits=24, coding=signed, full_scale_mvv=3.90625";
  cal.extra["recording_unit"] = "counts";
  cal.extra["converter"] = conv;
  const auto dir =
      std::filesystem::temp_directory_path() / ("ftcal_check_units_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string cal_path = (dir / "cal.json").string();
  ftstack::cal::SaveCalFile(cal_path, cal);
  Recording rec = Generate(cal, Tool(2.5), {}, 5);
  const double mvv_per_count = 3.90625 / 8388608.0;  // full scale over 2^23 codes
  for (std::size_t c = 5; c < rec.columns.size(); ++c)
    for (double& v : rec.columns[c]) v = std::nearbyint(v / mvv_per_count);
  auto run = [&](const std::vector<std::string>& metadata, std::string* text) {
    rec.metadata = metadata;
    const std::string in = (dir / "poses.csv").string();
    ftstack::WriteRecording(in, rec);
    ftstack::cal::CheckRequest req;
    req.cal_path = cal_path;
    req.in_path = in;
    req.mass_kg = 2.5;
    req.com_m = {0.012, -0.018, 0.085};
    return ftstack::cal::RunCheck(req, text);
  };
  std::string undeclared;
  std::string declared;
  const CheckResult a = run({}, &undeclared);
  const CheckResult b = run({"bridge_unit: counts", "converter: " + conv}, &declared);
  EXPECT_TRUE(a.pass) << undeclared;
  EXPECT_NE(undeclared.find("[calibration " + cal_path + "]"), std::string::npos) << undeclared;
  EXPECT_NE(declared.find("[metadata]"), std::string::npos) << declared;
  // Past the unit line the two reports are the same text.
  EXPECT_EQ(undeclared.substr(undeclared.find('\n')), declared.substr(declared.find('\n')));
  EXPECT_EQ(a.pass, b.pass);
  std::string text;
  try {
    (void)run({"bridge_unit: mV/V"}, &text);
    ADD_FAILURE() << "a recording declared in mV/V was accepted";
  } catch (const ftstack::RecordingError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("poses.csv:1: declares bridge unit mV/V"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
