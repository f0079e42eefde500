// Calibration with known masses: reference wrenches from mass, arm and gravity; the loading jig
// identified jointly with the calibration; data generated in the world frame through the built-in
// sensor model with its channel noise.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <random>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/fit.hpp"
#include "calibration/fit/known_mass.hpp"
#include "sim/sensor_description.hpp"
#include "sim/sensor_model.hpp"
#include "tests/calibration/run_ftcal.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using ftstack::Recording;

constexpr double kG = 9.80665;

Matrix3d Rpy(double r, double p, double y) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(y * d, Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p * d, Vector3d::UnitY()) * Eigen::AngleAxisd(r * d, Vector3d::UnitX()))
      .toRotationMatrix();
}

struct Jig {
  double mass_kg = 0.9;
  Vector3d com_m{0.003, -0.002, 0.045};
};

/// The wrench in the sensor frame of `mass` hanging at `point` (sensor frame) when the sensor has
/// orientation r — worked out in the world frame.
Eigen::Matrix<double, 6, 1> Load(const Matrix3d& r, double mass, const Vector3d& point) {
  const Vector3d weight(0, 0, -mass * kG);
  Eigen::Matrix<double, 6, 1> w;
  w.head<3>() = r.transpose() * weight;
  w.tail<3>() = r.transpose() * (r * point).cross(weight);
  return w;
}

/// A known-mass rig recording: orientations × (mass, arm) holds of 20 rows, with the jig always on.
/// `orientations` limits the set (1: one orientation only). *truth gets the total load per row.
Recording MakeRig(const Jig& jig, int orientations, std::vector<Eigen::Matrix<double, 6, 1>>* truth,
                  unsigned seed = 1) {
  const ftstack::sim::SensorDescription d = ftstack::sim::DefaultSensorDescription();
  const std::vector<Matrix3d> rs = {Rpy(0, 0, 0),    Rpy(180, 0, 0),   Rpy(90, 0, 0),
                                    Rpy(-90, 0, 60), Rpy(0, 90, 0),    Rpy(0, -90, 30),
                                    Rpy(45, 45, 0),  Rpy(-60, 30, 120)};
  const std::vector<std::pair<double, Vector3d>> holds = {{0.0, {0, 0, 0.08}},
                                                          {2.0, {0.05, 0, 0.08}},
                                                          {5.0, {0, -0.05, 0.08}},
                                                          {8.0, {-0.04, 0.03, 0.06}}};
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, d.adc.noise_rms_mvv);
  const int nb = d.model->channel_count();
  Recording rec;
  rec.path = "known_mass_rig.csv";
  rec.names = {"t",       "pose",    "mass_kg", "arm_x_m", "arm_y_m",
               "arm_z_m", "gx_mps2", "gy_mps2", "gz_mps2"};
  for (int c = 0; c < nb; ++c) rec.names.push_back("b" + std::to_string(c));
  rec.columns.resize(rec.names.size());
  int pose = 0;
  for (int o = 0; o < orientations; ++o) {
    const Matrix3d& r = rs[static_cast<std::size_t>(o)];
    const Vector3d g = r.transpose() * Vector3d(0, 0, -kG);
    for (const auto& [m, arm] : holds) {
      const Eigen::Matrix<double, 6, 1> total = Load(r, m, arm) + Load(r, jig.mass_kg, jig.com_m);
      const Eigen::VectorXd b = d.model->BridgeOutputs(total, 20.0);
      for (int k = 0; k < 20; ++k) {
        const double row[9] = {rec.rows() * 1e-3,
                               static_cast<double>(pose),
                               m,
                               arm.x(),
                               arm.y(),
                               arm.z(),
                               g.x(),
                               g.y(),
                               g.z()};
        for (int i = 0; i < 9; ++i) rec.columns[static_cast<std::size_t>(i)].push_back(row[i]);
        for (int c = 0; c < nb; ++c)
          rec.columns[static_cast<std::size_t>(9 + c)].push_back(b(c) + noise(rng));
        if (truth != nullptr) truth->push_back(total);
      }
      ++pose;
    }
  }
  return rec;
}

TEST(KnownMass, ReferenceIsTheKnownMassesLoadWorkedOutInTheWorldFrame) {
  const Jig no_jig{0.0, {0, 0, 0}};
  std::vector<Eigen::Matrix<double, 6, 1>> truth;
  const Recording rec = ftstack::cal::WithReferenceFromMasses(MakeRig(no_jig, 8, &truth));
  ASSERT_EQ(rec.rows(), truth.size());
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    for (std::size_t a = 0; a < 6; ++a) {
      ASSERT_NEAR(rec.Column(ftstack::WrenchColumns()[a])[i], truth[i](static_cast<int>(a)), 1e-9)
          << "row " << i << " axis " << a;
    }
  }
}

TEST(KnownMass, JigIsIdentifiedAndTheCalibrationReachesTheNoiseFloor) {
  const Jig jig;
  std::vector<Eigen::Matrix<double, 6, 1>> truth;
  const Recording rec = ftstack::cal::WithReferenceFromMasses(MakeRig(jig, 8, &truth));
  const ftstack::cal::JigEstimate est = ftstack::cal::IdentifyJig(rec);
  EXPECT_NEAR(est.mass_kg, jig.mass_kg, 0.01 * jig.mass_kg);
  EXPECT_LT(std::fabs(est.mass_kg - jig.mass_kg), 4 * est.mass_sigma_kg + 1e-6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(est.com_m[static_cast<std::size_t>(k)], jig.com_m(k), 1e-3) << k;
  }
  // The fit with the jig in the reference against the fit that ignores it.
  ftstack::cal::FitOptions fo;
  fo.models = {ftstack::cal::ModelKind::kLinear};
  fo.folds = 8;
  fo.rated = {200, 200, 400, 10, 10, 8};
  ftstack::cal::BlockOptions bo;
  bo.scale = fo.rated;
  const auto with = ftstack::cal::FitCalibration(
      ftstack::cal::RigDataFromRecording(ftstack::cal::WithJig(rec, est), bo), fo);
  const auto without =
      ftstack::cal::FitCalibration(ftstack::cal::RigDataFromRecording(rec, bo), fo);
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_LT(with.heldout_rms_si[a] * 5, without.heldout_rms_si[a]) << a;
  }
  // With the jig: the held-out error is the noise (well below 1e-3 of rated).
  for (std::size_t a = 0; a < 6; ++a) EXPECT_LT(with.heldout_rms_si[a], 1e-3 * fo.rated[a]) << a;
}

TEST(KnownMass, OneOrientationCannotSeparateTheJigAndSaysSo) {
  const Recording rec = ftstack::cal::WithReferenceFromMasses(MakeRig(Jig{}, 1, nullptr));
  try {
    (void)ftstack::cal::IdentifyJig(rec);
    FAIL() << "accepted";
  } catch (const ftstack::cal::JigIdentError& e) {
    EXPECT_NE(std::string(e.what()).find("jig's mass is not identifiable"), std::string::npos)
        << e.what();
  }
}

TEST(KnownMass, MissingColumnsAndBadValuesNameTheFile) {
  Recording rec = MakeRig(Jig{}, 2, nullptr);
  rec.data_lines.assign(rec.rows(), 0);
  for (std::size_t i = 0; i < rec.rows(); ++i) rec.data_lines[i] = i + 2;
  rec.Column("mass_kg")[3] = -1.0;
  try {
    (void)ftstack::cal::WithReferenceFromMasses(rec);
    FAIL();
  } catch (const ftstack::RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("known_mass_rig.csv:5: field 3 (mass_kg)"),
              std::string::npos)
        << e.what();
  }
  Recording no_g = MakeRig(Jig{}, 2, nullptr);
  no_g.names.erase(no_g.names.begin() + 8);
  no_g.columns.erase(no_g.columns.begin() + 8);
  EXPECT_THROW((void)ftstack::cal::WithReferenceFromMasses(no_g), ftstack::RecordingError);
}

using ftstack::test::RunFtcal;

TEST(FtcalFitKnownMass, FitsFromMassesAndReportsTheJig) {
  ftstack::test::TempDir dir("ftcal_known_mass");
  ftstack::WriteRecording(dir / "rig.csv", MakeRig(Jig{}, 8, nullptr));
  std::string out;
  ASSERT_EQ(RunFtcal("fit --in " + (dir / "rig.csv") + " --out " + (dir / "cal.json") +
                         " --model linear --folds 8 --identify-jig --rated 200,200,400,10,10,8",
                     &out),
            0)
      << out;
  const auto at = out.find("jig: ");
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_NEAR(std::stod(out.substr(at + 5)), Jig{}.mass_kg, 0.01 * Jig{}.mass_kg) << out;
  const ftstack::cal::CalFile cal = ftstack::cal::LoadCalFile(dir / "cal.json");
  EXPECT_EQ(cal.cal.channel_count, 6);
  ftstack::WriteRecording(dir / "flat.csv", MakeRig(Jig{}, 1, nullptr));
  out.clear();
  EXPECT_EQ(RunFtcal("fit --in " + (dir / "flat.csv") + " --out " + (dir / "c2.json") +
                         " --model linear --folds 2 --identify-jig --rated 200,200,400,10,10,8",
                     &out),
            1);
  EXPECT_NE(out.find("not identifiable"), std::string::npos) << out;
}

}  // namespace
