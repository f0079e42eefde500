// End-to-end tests of the built `ftsim pivot` binary against the exact solver and closed forms.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <tuple>

#include "sim/pivot/pivot.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim::pivot {
namespace {

struct CliRun {
  int exit_code = -1;
  std::string out;
};

// Runs `ftsim pivot ARGS`, capturing stdout (stderr is folded into stdout with 2>&1 when asked).
CliRun Ftsim(const std::string& args) {
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/ftsim pivot " + args;
  CliRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

const std::string kStrip = "--E 200e9 --L 0.098 --b 0.013 --t 0.5e-3 --alpha-deg 45 ";

TEST(PivotCli, JsonMatchesTheExactSolverAndTheClosedForm) {
  for (const auto& [theta, v, h] :
       {std::tuple{12.5, 8.0, -3.0}, std::tuple{-20.0, -60.0, 20.0}, std::tuple{1.0, 0.0, 0.0}}) {
    char args[160];
    std::snprintf(args, sizeof args, "--theta-deg %g --V %g --H %g --json", theta, v, h);
    const CliRun run = Ftsim(kStrip + args);
    ASSERT_EQ(run.exit_code, 0) << run.out;
    const auto j = nlohmann::json::parse(run.out);
    for (const char* key :
         {"C_Nm", "dX_m", "dY_m", "f1", "f2", "mB1", "mB2", "iterations", "valid", "reason"}) {
      EXPECT_TRUE(j.contains(key)) << key;
    }
    PivotGeometry g;  // the same strip, in SI units
    const PivotResult ref =
        SolvePivot(g, {theta * std::numbers::pi / 180, v, h}, PivotMethod::kExact);
    EXPECT_NEAR(j["C_Nm"].get<double>(), ref.c_nm, 1e-9 * std::abs(ref.c_nm));
    EXPECT_NEAR(j["dY_m"].get<double>(), ref.dy_m, 1e-9 * std::abs(ref.dy_m));
    EXPECT_NEAR(j["f1"].get<double>(), ref.f[0], 1e-9 * (1 + std::abs(ref.f[0])));
    EXPECT_NEAR(j["mB2"].get<double>(), ref.mb[1], 1e-9 * (1 + std::abs(ref.mb[1])));
    EXPECT_EQ(j["valid"].get<bool>(), ref.valid);
    EXPECT_EQ(j["method"].get<std::string>(), "exact");
  }
  // Units through the command line, checked against the closed form C ≈ 2·EI/L·θ at 1°, no load.
  const auto j = nlohmann::json::parse(Ftsim(kStrip + "--theta-deg 1 --V 0 --H 0 --json").out);
  const double ei = 200e9 * 0.013 * std::pow(0.5e-3, 3) / 12;
  EXPECT_NEAR(j["C_Nm"].get<double>() / (2 * ei / 0.098 * std::numbers::pi / 180), 1.0, 1e-3);
}

TEST(PivotCli, ReportCaseIsInvalidAndSaysWhy) {
  const CliRun run = Ftsim(kStrip + "--theta-deg 30 --V 100 --H 100 --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j["valid"].get<bool>());
  EXPECT_NE(j["reason"].get<std::string>().find("unstable"), std::string::npos);
}

TEST(PivotCli, BadNumbersGiveOneLineErrorAndNonZeroExit) {
  for (const std::string bad : {"--theta-deg abc --V 0 --H 0", "--theta-deg nan --V 0 --H 0",
                                "--theta-deg 5 --V 1e999 --H 0", "--theta-deg 5 --V 0 --H 3x",
                                "--theta-deg 95 --V 0 --H 0"}) {
    const CliRun run = Ftsim(kStrip + bad + " --json 2>&1");
    EXPECT_NE(run.exit_code, 0) << bad;
    EXPECT_EQ(run.out.rfind("ftsim pivot: ", 0), 0u) << run.out;
    EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
  }
  const CliRun method = Ftsim(kStrip + "--theta-deg 5 --V 0 --H 0 --method magic 2>&1");
  EXPECT_NE(method.exit_code, 0);
  const CliRun missing = Ftsim("--E 200e9 --theta-deg 5 2>&1");
  EXPECT_NE(missing.exit_code, 0);
}

// The camera experiment through the command line: points of the model's strip 2, "photographed"
// at 3000 px/m (rotated 40°, mirrored, shifted, 0.3 px noise), written to a CSV file.
TEST(PivotCli, ShapeCsvIsRegisteredOntoTheModelStrip) {
  PivotOptions o;
  o.want_shape = true;
  const PivotResult model =
      SolvePivot(PivotGeometry{}, {15 * std::numbers::pi / 180, 5.0, -3.0}, PivotMethod::kExact, o);
  ASSERT_TRUE(model.valid);
  const std::string path = ftstack::test::ProcessTempDir() + "pivot_shape_points.csv";
  {
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 0.3);
    const double a = 40 * std::numbers::pi / 180;
    std::ofstream f(path);
    f << "x_px,y_px\n";
    for (const auto& p : model.shape_m[1]) {
      const double x = 3000 * (std::cos(a) * p.x() - std::sin(a) * p.y()) + 800;
      const double y = -3000 * (std::sin(a) * p.x() + std::cos(a) * p.y()) + 600;
      f << x + noise(rng) << "," << y + noise(rng) << "\n";
    }
  }
  const CliRun run =
      Ftsim(kStrip + "--theta-deg 15 --V 5 --H -3 --json --strip 2 --shape-csv " + path);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_TRUE(j["shape"].is_object()) << run.out;
  EXPECT_NEAR(j["shape"]["scale_m_per_px"].get<double>() * 3000, 1.0, 5e-3);
  EXPECT_TRUE(j["shape"]["reflected"].get<bool>());
  // 201 points: the normal noise component 0.3 px, RMS scatter ≈ 1/√402 = 5 %.
  EXPECT_NEAR(j["shape"]["rms_residual_px"].get<double>() / 0.3, 1.0, 0.2);
  // The same points against the model under 80 N of compression (an S-bent strip) fit far worse.
  const auto other = nlohmann::json::parse(
      Ftsim(kStrip + "--theta-deg 15 --V -80 --H -3 --json --strip 2 --shape-csv " + path).out);
  EXPECT_GT(other["shape"]["rms_residual_px"].get<double>(), 5 * 0.3);

  // A bad file: one line naming file, line and column.
  const std::string bad = ftstack::test::ProcessTempDir() + "pivot_shape_bad.csv";
  {
    std::ofstream f(bad);
    f << "x,y\n1,2\n3,4\n5,zz\n";
  }
  const CliRun broken =
      Ftsim(kStrip + "--theta-deg 15 --V 5 --H -3 --json --shape-csv " + bad + " 2>&1");
  EXPECT_EQ(broken.exit_code, 2);
  EXPECT_NE(broken.out.find(bad + ":4:3: 'zz' is not a finite number"), std::string::npos)
      << broken.out;
  EXPECT_EQ(std::count(broken.out.begin(), broken.out.end(), '\n'), 1) << broken.out;
}

TEST(PivotCli, WittrickMethodIsSelectable) {
  const CliRun run = Ftsim(kStrip + "--theta-deg 5 --V 5 --H 0 --method wittrick --json");
  ASSERT_EQ(run.exit_code, 0);
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["method"].get<std::string>(), "wittrick");
  const PivotResult ref =
      SolvePivot(PivotGeometry{}, {5 * std::numbers::pi / 180, 5.0, 0.0}, PivotMethod::kExact);
  EXPECT_NEAR(j["C_Nm"].get<double>() / ref.c_nm, 1.0, 2e-2);
}

}  // namespace
}  // namespace ftstack::sim::pivot
