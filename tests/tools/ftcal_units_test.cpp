// `ftcal fit` + `ftcal apply` on raw converter counts (issue 12): a declared 10-bit converter is
// fitted and applied with no row flagged and an error no worse than plain least squares (Eigen,
// in this test); the same file undeclared is refused with one line naming file:line:column.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/tools/counts_rig.hpp"

namespace {

using namespace ftstack::test;  // NOLINT(google-build-using-namespace): the rig of these tests

/// Plain affine least squares on the training rows, evaluated on the held-out rows: RMS per axis.
std::array<double, 6> ReferenceRms(const std::vector<Row>& rows, int held_out_mod) {
  std::vector<const Row*> train;
  std::vector<const Row*> test;
  for (const Row& r : rows) (r.pose % 5 == held_out_mod ? test : train).push_back(&r);
  auto design = [](const std::vector<const Row*>& set, Eigen::MatrixXd* x, Eigen::MatrixXd* y) {
    x->resize(static_cast<Eigen::Index>(set.size()), 9);
    y->resize(static_cast<Eigen::Index>(set.size()), 6);
    for (std::size_t i = 0; i < set.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      for (int c = 0; c < 8; ++c) (*x)(k, c) = set[i]->code[static_cast<std::size_t>(c)];
      (*x)(k, 8) = 1.0;
      for (int a = 0; a < 6; ++a) (*y)(k, a) = set[i]->w[static_cast<std::size_t>(a)];
    }
  };
  Eigen::MatrixXd x;
  Eigen::MatrixXd y;
  design(train, &x, &y);
  const Eigen::MatrixXd beta = (x.transpose() * x).ldlt().solve(x.transpose() * y);
  design(test, &x, &y);
  const Eigen::MatrixXd e = x * beta - y;
  std::array<double, 6> rms{};
  for (int a = 0; a < 6; ++a)
    rms[static_cast<std::size_t>(a)] = std::sqrt(e.col(a).squaredNorm() / e.rows());
  return rms;
}

/// RMS per axis of `applied` (t,Fx…Mz,status) against the held-out rows' reference wrench.
std::array<double, 6> AppliedRms(const std::string& applied, const std::vector<Row>& rows,
                                 int held_out_mod, int* flagged) {
  std::ifstream in(applied);
  std::string line;
  while (std::getline(in, line) && line[0] == '#') {
  }
  std::array<double, 6> sum{};
  std::size_t n = 0;
  *flagged = 0;
  for (const Row& r : rows) {
    if (r.pose % 5 != held_out_mod) continue;
    EXPECT_TRUE(std::getline(in, line));
    std::stringstream ss(line);
    std::string f;
    std::vector<double> v;
    while (std::getline(ss, f, ',')) v.push_back(std::stod(f));
    EXPECT_EQ(v.size(), 8u);
    EXPECT_NEAR(v[0], r.t, 1e-6);
    for (int a = 0; a < 6; ++a) {
      const double e = v[static_cast<std::size_t>(a + 1)] - r.w[static_cast<std::size_t>(a)];
      sum[static_cast<std::size_t>(a)] += e * e;
    }
    *flagged += v[7] != 0.0 ? 1 : 0;
    ++n;
  }
  for (double& s : sum) s = std::sqrt(s / static_cast<double>(n));
  return sum;
}

TEST(FtcalUnits, DeclaredTenBitCountsFitAndApplyAsWellAsPlainLeastSquares) {
  Tmp tmp;
  const std::vector<Row> rows = Generate(12);
  for (const int mod : {0, 3}) {
    const std::string train = tmp / ("train" + std::to_string(mod) + ".csv");
    const std::string test = tmp / ("test" + std::to_string(mod) + ".csv");
    Write(train, rows, true, false, mod);
    Write(test, rows, true, true, mod);
    const std::string cal = tmp / "cal.json";
    const std::string model = mod == 0 ? " --model linear" : "";  // split 3: model chosen by CV
    ASSERT_EQ(RunFtcal("fit --in " + train + " --out " + cal + model + kRated, tmp / "fit.err"), 0)
        << Slurp(tmp / "fit.err");
    const std::string text = Slurp(cal);
    EXPECT_NE(text.find("\"input_unit\": \"mV/V\""), std::string::npos) << text.substr(0, 400);
    EXPECT_NE(text.find("bits=10, coding=unsigned"), std::string::npos);
    EXPECT_NE(text.find("\"max_counts\": 1023"), std::string::npos);
    EXPECT_NE(text.find("\"min_counts\": 0"), std::string::npos);
    const std::string out = tmp / "applied.csv";
    ASSERT_EQ(RunFtcal("apply --cal " + cal + " --in " + test + " --out " + out, tmp / "apply.err"),
              0)
        << Slurp(tmp / "apply.err");
    EXPECT_NE(Slurp(tmp / "apply.err").find("bridge unit counts"), std::string::npos);
    int flagged = -1;
    const auto got = AppliedRms(out, rows, mod, &flagged);
    const auto ref = ReferenceRms(rows, mod);
    EXPECT_EQ(flagged, 0);
    std::printf("split %d: held-out RMS ftcal / reference:", mod);
    for (std::size_t a = 0; a < 6; ++a) std::printf(" %.4g/%.4g", got[a], ref[a]);
    std::printf("\n");
    for (std::size_t a = 0; a < 6; ++a) {
      // Fixed point adds at most a few output LSB (1 mN, 0.1 mN·m) to the float fit.
      EXPECT_LE(got[a], ref[a] * 1.02 + 2e-3) << "axis " << a << " split " << mod;
      EXPECT_GT(ref[a], 0.0);
    }
  }
}

TEST(FtcalUnits, UndeclaredCountsAreRefusedWithOneLineNamingLineAndColumn) {
  Tmp tmp;
  const std::vector<Row> rows = Generate(5);
  const std::string train = tmp / "undeclared.csv";
  Write(train, rows, false, false, 0);
  EXPECT_EQ(
      RunFtcal("fit --in " + train + " --out " + (tmp / "cal.json") + kRated, tmp / "fit.err"), 1);
  const std::string err = Slurp(tmp / "fit.err");
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  // First data row is line 3 (one metadata line, the header); b0 is field 10.
  std::ifstream in(train);
  std::string line;
  for (int i = 0; i < 3; ++i) std::getline(in, line);
  std::size_t col = 1;
  for (int k = 0, i = 0; k < 9; ++i) {
    if (line[static_cast<std::size_t>(i)] == ',') {
      ++k;
      col = static_cast<std::size_t>(i) + 2;
    }
  }
  EXPECT_NE(err.find(train + ":3:" + std::to_string(col) + ": b0 = "), std::string::npos) << err;
  EXPECT_NE(err.find("declare the unit"), std::string::npos) << err;
  EXPECT_NE(err.find("assumed converter"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(tmp / "cal.json"));
  // Declared on the command line instead, the same file fits.
  EXPECT_EQ(RunFtcal("fit --in " + train + " --out " + (tmp / "cal.json") +
                         " --converter bits=10,coding=unsigned,gain=200" + kRated,
                     tmp / "fit2.err"),
            0)
      << Slurp(tmp / "fit2.err");
}

TEST(FtcalUnits, ApplyRefusesOutOfRangeCodesAndFlagsSaturatedRows) {
  Tmp tmp;
  const std::vector<Row> rows = Generate(7);
  Write(tmp / "train.csv", rows, true, false, 1);
  ASSERT_EQ(RunFtcal("fit --in " + (tmp / "train.csv") + " --out " + (tmp / "cal.json") +
                         " --model linear" + kRated,
                     tmp / "fit.err"),
            0);
  // A code beyond 10 bits: refused with one line, no output written.
  std::ofstream(tmp / "bad.csv") << "# bridge_unit: counts\n# converter: bits=10, coding=unsigned, "
                                    "gain=200\nt,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500,500,500,"
                                    "500,500,500\n0.01,500,500,1024,500,500,500,500,500\n";
  EXPECT_EQ(RunFtcal("apply --cal " + (tmp / "cal.json") + " --in " + (tmp / "bad.csv") +
                         " --out " + (tmp / "o.csv"),
                     tmp / "bad.err"),
            1);
  const std::string bad = Slurp(tmp / "bad.err");
  EXPECT_NE(bad.find("bad.csv:5:14: b2 = 1024 lies outside"), std::string::npos) << bad;
  EXPECT_FALSE(fs::exists(tmp / "o.csv"));
  // A code at the rail: the row is saturated (status bit 0): counted, exit 3 unless allowed.
  std::ofstream(tmp / "rail.csv") << "# converter: bits=10, coding=unsigned, gain=200\n"
                                     "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500,500,500,500,500,"
                                     "500\n0.01,500,500,1023,500,500,500,500,500\n";
  const std::string apply = "apply --cal " + (tmp / "cal.json") + " --in " + (tmp / "rail.csv") +
                            " --out " + (tmp / "o.csv");
  EXPECT_EQ(RunFtcal(apply, tmp / "rail.err"), 3);
  const std::string rail = Slurp(tmp / "rail.err");
  EXPECT_NE(rail.find("status bit 0 (saturated): 1 of 2 rows"), std::string::npos) << rail;
  EXPECT_EQ(RunFtcal(apply + " --allow-flagged", tmp / "rail2.err"), 0);
}

TEST(FtcalUnits, UndeclaredCountsApplyWithTheCalibrationsConverter) {
  Tmp tmp;
  const std::vector<Row> rows = Generate(9);
  ASSERT_TRUE(FitDeclared(tmp, rows));
  Write(tmp / "declared.csv", rows, true, true, 2);
  Write(tmp / "undeclared.csv", rows, false, true, 2);
  ASSERT_EQ(RunFtcal("apply --cal " + (tmp / "cal.json") + " --in " + (tmp / "declared.csv") +
                         " --out " + (tmp / "declared_out.csv"),
                     tmp / "declared.err"),
            0)
      << Slurp(tmp / "declared.err");
  ASSERT_EQ(RunFtcal("apply --cal " + (tmp / "cal.json") + " --in " + (tmp / "undeclared.csv") +
                         " --out " + (tmp / "undeclared_out.csv"),
                     tmp / "undeclared.err"),
            0)
      << Slurp(tmp / "undeclared.err");
  // The calibration's converter decided, and said so; the output is the declared one's.
  const std::string said = Slurp(tmp / "undeclared.err");
  EXPECT_NE(said.find("bridge unit counts of converter (bits=10, coding=unsigned, gain=200"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("[calibration " + (tmp / "cal.json") + "]"), std::string::npos) << said;
  EXPECT_NE(Slurp(tmp / "declared.err").find("[metadata]"), std::string::npos);
  const std::string declared_out = DataLines(tmp / "declared_out.csv");
  EXPECT_GT(declared_out.size(), 1000u);
  EXPECT_EQ(DataLines(tmp / "undeclared_out.csv"), declared_out);
}

TEST(FtcalUnits, ApplyRefusesADeclarationOtherThanTheCalibrationsAndNonWholeCodes) {
  Tmp tmp;
  const std::vector<Row> rows = Generate(9);
  ASSERT_TRUE(FitDeclared(tmp, rows));
  const std::string body = "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500,500,500,500,500,500\n";
  auto refused = [&](const std::string& name, const std::string& text, const std::string& opts) {
    std::ofstream(tmp / name) << text;
    const int rc = RunFtcal("apply --cal " + (tmp / "cal.json") + " --in " + (tmp / name) +
                                " --out " + (tmp / "o.csv") + opts,
                            tmp / "err");
    EXPECT_EQ(rc, 1) << name;
    EXPECT_FALSE(fs::exists(tmp / "o.csv")) << name;
    const std::string err = Slurp(tmp / "err");
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    return err;
  };
  // Another converter declared in the file: refused at its metadata line.
  std::string err = refused(
      "twelve.csv", "# sensor: x\n# converter: bits=12, coding=unsigned, gain=200\n" + body, "");
  EXPECT_NE(err.find("twelve.csv:2: declares bridge unit counts of converter (bits=12"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("was fitted from counts of converter (bits=10"), std::string::npos) << err;
  // mV/V declared in the file, or another converter on the command line.
  err = refused("mvv.csv", "# bridge_unit: mV/V\n" + body, "");
  EXPECT_NE(err.find("mvv.csv:1: declares bridge unit mV/V"), std::string::npos) << err;
  err = refused("plain.csv", body, " --converter bits=10,coding=offset-binary,gain=200");
  EXPECT_NE(err.find("--bridge-unit/--converter: declares bridge unit counts"), std::string::npos)
      << err;
  // Undeclared, so read as the calibration's counts: 500.5 is no code of any converter.
  err = refused("half.csv", "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500.5,500,500,500,500,500\n", "");
  EXPECT_NE(err.find("half.csv:2:11: b2 = 500.5 is not a whole code"), std::string::npos) << err;
}

}  // namespace
