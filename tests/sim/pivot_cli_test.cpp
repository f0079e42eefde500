// End-to-end tests of the built `ftsim pivot` binary against the exact solver and closed forms.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <tuple>

#include "sim/pivot/pivot.hpp"

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
