// `ftcal apply` runs the firmware's fixed-point core on a recording: checked against double
// precision.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "measurement/recording.hpp"
#include "sim/default_sensor.hpp"
#include "sim/ideal_calibration.hpp"

namespace ftstack {
namespace {

namespace fs = std::filesystem;

struct Tmp {
  fs::path dir = fs::temp_directory_path() / ("ftcal_apply_" + std::to_string(::getpid()));
  Tmp() { fs::create_directories(dir); }
  ~Tmp() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

int RunFtcal(const std::string& args, const std::string& stderr_path) {
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/ftcal " + args + " 2>" + stderr_path;
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(FtcalApply, MatchesDoublePrecisionWithinInputQuantisationAndFixedPointBound) {
  Tmp tmp;
  const auto model = sim::MakeDefaultSensor();
  const cal::CalFile cal = sim::IdealCalibration(*model, cal::DefaultAdc(6));
  cal::SaveCalFile(tmp / "cal.json", cal);

  // A recording of random wrenches inside the rated range, noise-free bridge outputs.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Recording rec;
  rec.names = {"t", "b0", "b1", "b2", "b3", "b4", "b5", "note"};
  rec.columns.assign(rec.names.size(), {});
  const int rows = 500;
  for (int i = 0; i < rows; ++i) {
    Wrench w;
    for (int k = 0; k < 6; ++k) w(k) = u(rng) * model->rated()(k);
    const Eigen::VectorXd b = model->BridgeOutputs(w, 20.0);
    rec.columns[0].push_back(i * 0.001);
    for (int c = 0; c < 6; ++c) rec.columns[static_cast<std::size_t>(c + 1)].push_back(b(c));
    rec.columns[7].push_back(i);  // unknown column: ignored
  }
  WriteRecording(tmp / "in.csv", rec);
  ASSERT_EQ(RunFtcal("apply --cal " + tmp / "cal.json" + " --in " + tmp / "in.csv" + " --out " +
                         tmp / "out.csv",
                     tmp / "err.txt"),
            0)
      << Slurp(tmp / "err.txt");
  const Recording in = ReadRecording(tmp / "in.csv");
  const Recording out = ReadRecording(tmp / "out.csv");
  ASSERT_EQ(out.rows(), static_cast<std::size_t>(rows));

  fw::LoadReport rep{};
  (void)cal::ToFixed(cal, cal.adc, &rep);
  const double cpm = fw::CountsPerMvv(cal.adc);
  const auto& names = WrenchColumns();
  for (std::size_t r = 0; r < 6; ++r) {
    // Inputs are rounded to whole counts (±0.5 count per channel) before the core.
    double tol = rep.worst_case_error_si[r];
    for (std::size_t c = 0; c < 6; ++c) tol += std::fabs(cal.cal.matrix[r][c]) * 0.5 / cpm;
    for (int i = 0; i < rows; ++i) {
      double ref = cal.cal.bias[r];
      for (std::size_t c = 0; c < 6; ++c) {
        ref += cal.cal.matrix[r][c] *
               (in.Column("b" + std::to_string(c))[static_cast<std::size_t>(i)] -
                cal.cal.offset_mvv[c]);
      }
      ASSERT_NEAR(out.Column(names[r])[static_cast<std::size_t>(i)], ref, tol)
          << names[r] << " row " << i;
    }
  }
  EXPECT_DOUBLE_EQ(out.Column("t")[10], in.Column("t")[10]);
}

TEST(FtcalApply, BadInputGivesOneLineErrorWithPosition) {
  Tmp tmp;
  const auto model = sim::MakeDefaultSensor();
  cal::SaveCalFile(tmp / "cal.json", sim::IdealCalibration(*model, cal::DefaultAdc(6)));
  {
    std::ofstream f(tmp / "bad.csv");
    f << "t,b0,b1,b2,b3,b4,b5\n0,0,0,0,0,0,0\n0.001,0,0,nan,0,0,0\n";
  }
  EXPECT_NE(RunFtcal("apply --cal " + tmp / "cal.json" + " --in " + tmp / "bad.csv" + " --out " +
                         tmp / "out.csv",
                     tmp / "err.txt"),
            0);
  const std::string err = Slurp(tmp / "err.txt");
  EXPECT_NE(err.find("bad.csv:3:11:"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  {
    std::ofstream f(tmp / "four.csv");
    f << "t,b0,b1,b2,b3\n0,0,0,0,0\n";
  }
  EXPECT_NE(RunFtcal("apply --cal " + tmp / "cal.json" + " --in " + tmp / "four.csv" + " --out " +
                         tmp / "out.csv",
                     tmp / "err.txt"),
            0);
  EXPECT_NE(Slurp(tmp / "err.txt").find("needs 6"), std::string::npos);
  // A calibration file with one flipped digit is refused by CRC.
  std::string text = Slurp(tmp / "cal.json");
  const auto pos = text.find("\"bias\"");
  ASSERT_NE(pos, std::string::npos);
  const auto digit = text.find_first_of("123456789", pos);
  text[digit] = text[digit] == '9' ? '8' : static_cast<char>(text[digit] + 1);
  std::ofstream(tmp / "corrupt.json") << text;
  EXPECT_NE(RunFtcal("verify " + tmp / "corrupt.json", tmp / "err.txt"), 0);
  EXPECT_NE(Slurp(tmp / "err.txt").find("CRC mismatch"), std::string::npos)
      << Slurp(tmp / "err.txt");
  EXPECT_EQ(RunFtcal("verify " + tmp / "cal.json", tmp / "err.txt"), 0);
}

}  // namespace
}  // namespace ftstack
