// ftd --adc replay on raw converter counts: a recording that declares no unit is played in the
// unit and converter its calibration was fitted from (the same log as with the declaration, and
// the generator's wrench within the fit's error); a conflicting declaration and values that
// cannot be counts are refused with exit 2 and one line naming the file and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "tests/system/ftd_process.hpp"
#include "tests/tools/counts_rig.hpp"

namespace {

using namespace ftstack::test;  // NOLINT(google-build-using-namespace): the rig of these tests

/// Runs ftd on `replay` with tmp/cal.json, as fast as it reads, logging to `log`; exit code and
/// stderr.
int RunReplay(const Tmp& tmp, const std::string& replay, const std::string& log,
              std::vector<std::string> extra, std::string* err) {
  std::vector<std::string> args = {"--adc", "replay",         "--replay",  replay,
                                   "--cal", tmp / "cal.json", "--unpaced", "--print-hz",
                                   "0",     "--log",          log};
  args.insert(args.end(), extra.begin(), extra.end());
  FtdProcess p(args, false);
  const int rc = p.Wait(30.0);
  *err = p.Stderr();
  return rc;
}

/// The columns Fx … Mz and status of an ftd log, row by row.
std::vector<std::vector<double>> LoggedWrench(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string f;
    std::vector<std::string> fields;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (names.empty()) {
      names = fields;
      continue;
    }
    std::vector<double> row;
    for (const char* want : {"Fx", "Fy", "Fz", "Mx", "My", "Mz", "status"}) {
      const auto it = std::find(names.begin(), names.end(), want);
      if (it == names.end()) return {};
      row.push_back(std::stod(fields[static_cast<std::size_t>(it - names.begin())]));
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(FtdReplayUnits, UndeclaredCountsPlayWithTheCalibrationsConverter) {
  Tmp tmp("ftd_replay_units");
  const std::vector<Row> rows = Generate(9);
  ASSERT_TRUE(FitDeclared(tmp, rows));
  Write(tmp / "declared.csv", rows, true, true, 2);
  Write(tmp / "undeclared.csv", rows, false, true, 2);
  std::string err;
  ASSERT_EQ(RunReplay(tmp, tmp / "declared.csv", tmp / "declared_log.csv", {}, &err), 0) << err;
  EXPECT_NE(err.find("[metadata]"), std::string::npos) << err;
  ASSERT_EQ(RunReplay(tmp, tmp / "undeclared.csv", tmp / "undeclared_log.csv", {}, &err), 0) << err;
  // The calibration's converter decided, and ftd said so.
  EXPECT_NE(err.find("bridge unit counts of converter (bits=10, coding=unsigned, gain=200"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("[calibration " + (tmp / "cal.json") + "]"), std::string::npos) << err;
  const auto declared = LoggedWrench(tmp / "declared_log.csv");
  const auto undeclared = LoggedWrench(tmp / "undeclared_log.csv");
  std::vector<const Row*> test;
  for (const Row& r : rows) {
    if (r.pose % 5 == 2) test.push_back(&r);
  }
  ASSERT_EQ(declared.size(), test.size());
  EXPECT_EQ(undeclared, declared);
  // The firmware path of ftcal apply on the declared recording gives the same wrench.
  ASSERT_EQ(RunFtcal("apply --cal " + (tmp / "cal.json") + " --in " + (tmp / "declared.csv") +
                         " --out " + (tmp / "applied.csv"),
                     tmp / "apply.err"),
            0)
      << Slurp(tmp / "apply.err");
  const auto applied = LoggedWrench(tmp / "applied.csv");
  ASSERT_EQ(applied.size(), test.size());
  const std::array<double, 6> lsb = {1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5};
  for (std::size_t i = 0; i < test.size(); ++i) {
    for (std::size_t a = 0; a < 6; ++a) {
      ASSERT_NEAR(undeclared[i][a], applied[i][a], 0.5 * lsb[a]) << "row " << i << " axis " << a;
    }
  }
  // Against the generator's wrench: the held-out error of a linear fit of 0.6-count noise on a
  // 10-bit converter (a few % of rated; ftcal_units_test holds it to plain least squares), far
  // below what counts read as another unit would give.
  const std::array<double, 6> rated = {40.0, 40.0, 80.0, 2.0, 2.0, 1.5};
  for (std::size_t a = 0; a < 6; ++a) {
    double sum = 0;
    for (std::size_t i = 0; i < test.size(); ++i) {
      const double e = undeclared[i][a] - test[i]->w[a];
      sum += e * e;
    }
    const double rms = std::sqrt(sum / static_cast<double>(test.size()));
    std::printf("axis %zu: held-out RMS %.4g (%.2f %% of rated)\n", a, rms, 100 * rms / rated[a]);
    EXPECT_LT(rms, 0.05 * rated[a]) << "axis " << a;
  }
}

TEST(FtdReplayUnits, AConflictingDeclarationOrValuesThatAreNoCountsAreRefused) {
  Tmp tmp("ftd_replay_refused");
  ASSERT_TRUE(FitDeclared(tmp, Generate(9)));
  const std::string body = "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500,500,500,500,500,500\n";
  auto refused = [&](const std::string& name, const std::string& text,
                     std::vector<std::string> opts) {
    std::ofstream(tmp / name) << text;
    std::string err;
    EXPECT_EQ(RunReplay(tmp, tmp / name, tmp / "log.csv", std::move(opts), &err), 2) << name;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(err.rfind("ftd: ", 0), 0u) << err;
    EXPECT_FALSE(fs::exists(tmp / "log.csv")) << name;
    return err;
  };
  std::string err = refused(
      "twelve.csv", "# sensor: x\n# converter: bits=12, coding=unsigned, gain=200\n" + body, {});
  EXPECT_NE(err.find("twelve.csv:2: declares bridge unit counts of converter (bits=12"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("was fitted from counts of converter (bits=10"), std::string::npos) << err;
  err = refused("mvv.csv", "# bridge_unit: mV/V\n" + body, {});
  EXPECT_NE(err.find("mvv.csv:1: declares bridge unit mV/V"), std::string::npos) << err;
  err = refused("plain.csv", body, {"--converter", "bits=10,coding=offset-binary,gain=200"});
  EXPECT_NE(err.find("--bridge-unit/--converter: declares bridge unit counts"), std::string::npos)
      << err;
  // Undeclared, so the calibration's counts: 500.5 is no code, 1024 beyond 10 bits.
  err = refused("half.csv", "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,500.5,500,500,500,500,500\n", {});
  EXPECT_NE(err.find("half.csv:2:11: b2 = 500.5 is not a whole code"), std::string::npos) << err;
  err = refused("high.csv", "t,b0,b1,b2,b3,b4,b5,b6,b7\n0,500,500,1024,500,500,500,500,500\n", {});
  EXPECT_NE(err.find("high.csv:2:11: b2 = 1024 lies outside"), std::string::npos) << err;
}

TEST(FtdReplayUnits, ReplayNeedsItsCalibration) {
  Tmp tmp("ftd_replay_nocal");
  std::ofstream(tmp / "r.csv") << "t,b0\n0,1\n";
  FtdProcess p({"--adc", "replay", "--replay", tmp / "r.csv", "--print-hz", "0"}, false);
  EXPECT_EQ(p.Wait(10.0), 2);
  const std::string err = p.Stderr();
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("--adc replay needs --replay REC.csv and --cal CAL.json"), std::string::npos)
      << err;
}

}  // namespace
