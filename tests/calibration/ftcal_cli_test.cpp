// ftcal end to end: design → simulated rig → fit (with report) → verify → apply; error exits.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "calibration/file/cal_file.hpp"
#include "measurement/recording.hpp"
#include "sim/sensor_description.hpp"
#include "tests/calibration/test_models.hpp"
#include "tests/support/chromium.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int code;
  std::string out;
};

/// Runs one of the built programs with `args`; exit code and stdout + stderr.
CliRun Tool(const std::string& name, const std::string& args) {
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/" + name + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (p != nullptr && std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = p != nullptr ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}
CliRun Ftcal(const std::string& args) { return Tool("ftcal", args); }

class FtcalCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ftcal_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (std::getenv("FTCAL_KEEP") == nullptr) fs::remove_all(dir_);
  }
  std::string P(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(FtcalCli, DesignFitVerifyApply) {
  CliRun r = Ftcal("design --sensor builtin --rate-hz 100 --out " + P("profile.csv") +
                   " --simulate " + P("rig.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("condition number of the load set"), std::string::npos);
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal.json") + " --report " +
            P("report.html") + " --sensor builtin --serial SN1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("held-out"), std::string::npos);
  EXPECT_NE(r.out.find("model: linear"), std::string::npos) << r.out;
  // The report is self-contained: inline SVG, no external references.
  std::ifstream html(P("report.html"));
  std::stringstream ss;
  ss << html.rdbuf();
  EXPECT_NE(ss.str().find("<svg"), std::string::npos);
  EXPECT_EQ(ss.str().find("http://"), ss.str().find("http://www.w3.org"));  // only the SVG xmlns
  EXPECT_EQ(ss.str().find("https://"), std::string::npos);
  // 1 bar chart + 6 residual plots, and headless Chromium renders it to a non-trivial image.
  std::size_t svgs = 0;
  for (std::size_t at = ss.str().find("<svg"); at != std::string::npos;
       at = ss.str().find("<svg", at + 1)) {
    ++svgs;
  }
  EXPECT_EQ(svgs, 7u);
  if (ftstack::test::HaveChromium()) {
    const std::string png = P("report.png");
    ASSERT_TRUE(ftstack::test::RenderWithChromium(P("report.html"), png, P("chrome")));
    EXPECT_GT(fs::file_size(png), 50000u);  // a blank 1200×1600 page compresses to a few kB
  }
  r = Ftcal("verify " + P("cal.json"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("OK"), std::string::npos);
  r = Ftcal("apply --cal " + P("cal.json") + " --in " + P("rig.csv") + " --out " + P("out.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  const ftstack::Recording in = ftstack::ReadRecording(P("rig.csv"));
  const ftstack::Recording out = ftstack::ReadRecording(P("out.csv"));
  ASSERT_EQ(in.rows(), out.rows());
  // Fz within 5 noise σ (≈ 0.04 N) of the reference on every row.
  const auto& ref = in.Column("Fz");
  const auto& got = out.Column("Fz");
  for (std::size_t i = 0; i < ref.size(); ++i) ASSERT_NEAR(got[i], ref[i], 0.2) << i;
}

TEST_F(FtcalCli, FitWithoutSensorNeedsTheRatedRangeAndTakesNothingFromDesign) {
  CliRun r = Ftcal("design --sensor builtin --rate-hz 50 --simulate " + P("rig.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  // Neither --sensor nor --rated: refused in one line naming both (it used to take the built-in
  // sensor's rating and converter silently, through a variable shared with design's default).
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal.json"));
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("--rated"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--sensor"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(P("cal.json")));
  // --rated alone: that rating, and the generic converter the help names (not the built-in
  // sensor's ADS131M at gain 128), said on stdout.
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal.json") +
            " --rated 400,400,800,20,20,16");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("converter: generic 24-bit"), std::string::npos) << r.out;
  const ftstack::cal::CalFile cal = ftstack::cal::LoadCalFile(P("cal.json"));
  const std::array<double, 6> rated = {400, 400, 800, 20, 20, 16};
  EXPECT_EQ(cal.rated, rated);
  EXPECT_EQ(cal.adc.full_scale_nvv, 3906250);  // ±3.90625 mV/V
  EXPECT_EQ(cal.adc.max_counts, (1 << 23) - 1);
  // --sensor builtin: its converter, not the generic one.
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal_b.json") + " --sensor builtin");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("converter: generic"), std::string::npos) << r.out;
  EXPECT_NE(ftstack::cal::LoadCalFile(P("cal_b.json")).adc.full_scale_nvv, 3906250);
}

/// Runs ftsim (the record helper's generator, with its effects) and fits its "real" output.
CliRun Ftsim(const std::string& args) { return Tool("ftsim", args); }

/// Copies the keyframe profile `in` (ftcal design --out) with Mz replaced by f(row's wrench).
template <typename MzOf>
void RewriteMz(const std::string& in, const std::string& out, MzOf mz_of) {
  ftstack::Recording prof = ftstack::ReadRecording(in);
  const std::vector<double> fx = prof.Column("Fx");
  std::vector<double>& mz = prof.Column("Mz");
  for (std::size_t i = 0; i < mz.size(); ++i) mz[i] = mz_of(fx[i]);
  ftstack::WriteRecording(out, prof);
}

TEST_F(FtcalCli, ARigThatNeverLoadsAnAxisIsRefusedNamingIt) {
  // The rig's load sequence as designed, then played by the simulator (ftsim record, an
  // independent generator of the bridges) without Mz — and with Mz only ever tied to Fx.
  CliRun r = Ftcal("design --sensor builtin --out " + P("profile.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  RewriteMz(P("profile.csv"), P("no_mz.csv"), [](double) { return 0.0; });
  RewriteMz(P("profile.csv"), P("tied.csv"), [](double fx) { return 0.04 * fx; });
  r = Ftsim("record --sensor builtin --profile " + P("no_mz.csv") + " --rate-hz 100 --out " +
            P("rig.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  // Before: exit 0, an Mz row of zeros with uncertainty 0, and verify said OK.
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal.json") + " --sensor builtin");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;  // one line
  EXPECT_NE(r.out.find("axis Mz not excited"), std::string::npos) << r.out;
  for (const char* other : {"Fx:", "Fy:", "Fz:", "Mx:", "My:"}) {
    EXPECT_EQ(r.out.find(other), std::string::npos) << other << " named: " << r.out;
  }
  EXPECT_FALSE(fs::exists(P("cal.json")));
  // Asked for: written with Mz flagged invalid (schema 3), said on stdout; verify never says OK
  // alone (exit 3, INCOMPLETE naming Mz).
  r = Ftcal("fit --in " + P("rig.csv") + " --out " + P("cal.json") +
            " --sensor builtin --allow-unexcited");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("flagged invalid"), std::string::npos) << r.out;
  const ftstack::cal::CalFile cal = ftstack::cal::LoadCalFile(P("cal.json"));
  EXPECT_EQ(cal.cal.invalid_axes, 1u << 5);
  r = Ftcal("verify " + P("cal.json"));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("INCOMPLETE: axis Mz flagged invalid"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(": OK"), std::string::npos) << r.out;
  // Mz loaded only in proportion to Fx (a lever that never changes): the load set lacks the
  // rank to tell them apart, so both are named.
  r = Ftsim("record --sensor builtin --profile " + P("tied.csv") + " --rate-hz 100 --out " +
            P("tied_rig.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  r = Ftcal("fit --in " + P("tied_rig.csv") + " --out " + P("tied.json") + " --sensor builtin");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("axes Fx, Mz not excited"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("independent of the other axes 0.0 %"), std::string::npos) << r.out;
}

TEST_F(FtcalCli, ImportAtiThenInstallIntoSlots) {
  const std::string ati = ftstack::test::TestDataPath("ati/FT11712.cal");
  CliRun r = Ftcal("import-ati " + ati + " --out " + P("ati.json"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("version 1.0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rated 200"), std::string::npos) << r.out;  // Fz max
  r = Ftcal("verify " + P("ati.json"));
  EXPECT_EQ(r.code, 0) << r.out;
  r = Ftcal("install " + P("ati.json") + " --slots " + P("dev"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("slot A"), std::string::npos) << r.out;
  // A truncated file is refused and slot A stays active.
  {
    std::ifstream in(P("ati.json"));
    std::stringstream ss;
    ss << in.rdbuf();
    std::ofstream(P("cut.json")) << ss.str().substr(0, ss.str().size() / 2);
  }
  r = Ftcal("install " + P("cut.json") + " --slots " + P("dev"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("cut.json:"), std::string::npos) << r.out;
  r = Ftcal("active --slots " + P("dev"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("slot A: serial FT11712"), std::string::npos) << r.out;
}

TEST_F(FtcalCli, RecordingsFromFtsimWithEffectsPickTheRightModelAtTheNoiseFloor) {
  const auto floor = ftstack::testing::NoiseFloor(ftstack::sim::DefaultSensorDescription());
  struct Scenario {
    std::string args;
    std::string model;
  };
  const Scenario scenarios[] = {
      // A nonlinearity of each bridge alone: its square, no cross products.
      {"--profile rig --effect bridge_nonlinearity:channels=[0,3] --seed 3", "quadratic-diag"},
      {"--profile thermal --effect thermal_zero_drift --effect thermal_span_drift --seed 4",
       "linear-temp"},
  };
  for (const Scenario& sc : scenarios) {
    CliRun r = Ftsim("record --sensor builtin --out " + P("real.csv") + " " + sc.args);
    ASSERT_EQ(r.code, 0) << r.out;
    r = Ftcal("fit --in " + P("real.csv") + " --out " + P("cal.json") + " --sensor builtin");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("model: " + sc.model + ","), std::string::npos) << sc.args << "\n"
                                                                         << r.out;
    const ftstack::cal::CalFile cal = ftstack::cal::LoadCalFile(P("cal.json"));
    for (int a = 0; a < 6; ++a) {
      EXPECT_LE(cal.uncertainty[static_cast<std::size_t>(a)], 1.1 * floor(a))
          << sc.args << " axis " << a;
    }
  }
}

TEST_F(FtcalCli, BadInputsExitNonZeroWithFileAndPosition) {
  {
    std::ofstream f(P("bad.csv"));
    f << "t,Fx,Fy,Fz,Mx,My,Mz,b0\n0,0,0,0,0,0,0,0.1\n1,0,0,abc,0,0,0,0.1\n";
  }
  CliRun r = Ftcal("fit --in " + P("bad.csv") + " --out " + P("cal.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("bad.csv:3:"), std::string::npos) << r.out;
  {
    std::ofstream f(P("nowrench.csv"));
    f << "t,b0\n0,0.1\n";
  }
  r = Ftcal("fit --in " + P("nowrench.csv") + " --out " + P("cal.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("nowrench.csv"), std::string::npos) << r.out;
  r = Ftcal("verify " + P("missing.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("missing.json"), std::string::npos);
  r = Ftcal("fit --in " + P("bad.csv") + " --out " + P("c.json") + " --model cubic");
  EXPECT_NE(r.code, 0);
}

}  // namespace
