// ftdiag command line: the spec's JSON keys, exit codes, one-line errors naming file:line:column.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "measurement/recording.hpp"
#include "tests/diagnosis/diag_fixture.hpp"

namespace ftstack::diag {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int code = 0;
  std::string err;
};

CliRun Ftdiag(const std::string& args) {
  const fs::path err = fs::temp_directory_path() / ("ftdiag_err_" + std::to_string(::getpid()));
  const std::string cmd =
      std::string(FTSTACK_BIN_DIR) + "/ftdiag " + args + " > /dev/null 2> " + err.string();
  const int rc = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WEXITSTATUS(rc), ss.str()};
}

class DiagCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ftdiag_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  /// Writes the fixture as sim.csv / real.csv (recording-format.md).
  void WritePair(const testing::Fixture& fx) {
    const auto& d = fx.data;
    Recording sim;
    Recording real;
    sim.SetColumn("t", d.t_s);
    real.SetColumn("t", d.t_s);
    for (int k = 0; k < 6; ++k) {
      std::vector<double> col(d.rows());
      for (std::size_t i = 0; i < d.rows(); ++i) col[i] = d.wrench(static_cast<Eigen::Index>(i), k);
      sim.SetColumn(WrenchColumns()[static_cast<std::size_t>(k)], col);
      real.SetColumn(WrenchColumns()[static_cast<std::size_t>(k)], col);
    }
    for (int c = 0; c < d.channels(); ++c) {
      std::vector<double> s(d.rows());
      std::vector<double> r(d.rows());
      for (std::size_t i = 0; i < d.rows(); ++i) {
        s[i] = d.sim_mvv(static_cast<Eigen::Index>(i), c);
        r[i] = d.real_mvv(static_cast<Eigen::Index>(i), c);
      }
      sim.SetColumn("b" + std::to_string(c), s);
      real.SetColumn("b" + std::to_string(c), r);
    }
    real.SetColumn("temp_C", d.temp_c);
    WriteRecording(P("sim.csv"), sim);
    WriteRecording(P("real.csv"), real);
  }
  std::string P(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(DiagCli, WritesTheSpecJsonAndHtml) {
  WritePair(testing::MakeFixture({{"gain_error", 6}}, 4, 200.0, 1e-4, 2.0));
  const CliRun r = Ftdiag("diagnose --sim " + P("sim.csv") + " --real " + P("real.csv") +
                          " --json " + P("out.json") + " --html " + P("out.html"));
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(P("out.json"));
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["schema"], "ftdiag-report/1");
  EXPECT_NEAR(j["rate_hz"].get<double>(), 200.0, 1e-6);
  for (const char* k : {"noise_rms", "rms_before"}) EXPECT_EQ(j[k].size(), 6u) << k;
  EXPECT_TRUE(j["mismatch"]["channels"].is_array());
  EXPECT_TRUE(j["mismatch"]["windows"].is_array());
  EXPECT_EQ(j["verdict"], "gain_error");
  ASSERT_GE(j["effects"].size(), 1u);
  const auto& e = j["effects"][0];
  EXPECT_EQ(e["name"], "gain_error");
  EXPECT_EQ(e["channels"], (std::vector<int>{3}));
  EXPECT_TRUE(e["params"].contains("gain"));
  EXPECT_TRUE(e["params"].contains("channels"));
  EXPECT_TRUE(e["evidence"].is_string());
  EXPECT_EQ(e["rms_after"].size(), 6u);
  EXPECT_LT(j["holdout"]["rms_after"].get<double>(), j["holdout"]["rms_before"].get<double>());
  EXPECT_EQ(j["mismatch"]["channels"], (std::vector<int>{3}));
  std::ifstream h(P("out.html"));
  std::stringstream hs;
  hs << h.rdbuf();
  EXPECT_NE(hs.str().find("<svg"), std::string::npos);
  EXPECT_EQ(hs.str().find("http://"),
            hs.str().find("http://www.w3.org/2000/svg"));  // no network references
  // It renders offline in headless Chromium (when installed): a screenshot of real size appears.
  if (std::system("command -v chromium > /dev/null 2>&1") == 0) {
    const std::string shot = P("shot.png");
    const std::string cmd =
        "timeout 90 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
        "--disable-background-networking --disable-component-update --disable-sync "
        "--user-data-dir=" +
        P("chrome") + " --screenshot=" + shot + " --window-size=1200,2400 file://" + P("out.html") +
        " > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    ASSERT_TRUE(fs::exists(shot));
    EXPECT_GT(fs::file_size(shot), 50000u);  // a blank 1200×2400 PNG is a few kB
  }
}

TEST_F(DiagCli, RefusesBadInputWithOneLineNamingTheFile) {
  WritePair(testing::MakeFixture({}, 5, 200.0, 1e-4, 1.0));
  // t that does not line up.
  {
    std::ifstream in(P("sim.csv"));
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const auto pos = text.find("\n0.01,");
    ASSERT_NE(pos, std::string::npos);
    text.replace(pos, 6, "\n0.0125,");
    std::ofstream(P("skew.csv")) << text;
  }
  CliRun r = Ftdiag("diagnose --sim " + P("skew.csv") + " --real " + P("real.csv") + " --json " +
                    P("o.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("skew.csv:"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // NaN in the real file.
  {
    std::ifstream in(P("real.csv"));
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const auto line3 = text.find('\n', text.find('\n') + 1);
    const auto comma = text.find(',', line3 + 1);
    text.replace(comma + 1, text.find(',', comma + 1) - comma - 1, "nan");
    std::ofstream(P("nan.csv")) << text;
  }
  r = Ftdiag("diagnose --sim " + P("sim.csv") + " --real " + P("nan.csv") + " --json " +
             P("o.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("nan.csv:3:"), std::string::npos) << r.err;
  // Missing file, both --sim and --model, a file without bridges.
  r = Ftdiag("diagnose --sim " + P("missing.csv") + " --real " + P("real.csv") + " --json " +
             P("o.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("missing.csv"), std::string::npos);
  r = Ftdiag("diagnose --sim " + P("sim.csv") + " --model builtin --real " + P("real.csv") +
             " --json " + P("o.json"));
  EXPECT_NE(r.code, 0);
  std::ofstream(P("nob.csv")) << "t,Fx\n0,1\n0.005,2\n";
  r = Ftdiag("diagnose --sim " + P("nob.csv") + " --real " + P("real.csv") + " --json " +
             P("o.json"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("nob.csv:1:"), std::string::npos) << r.err;
}

TEST_F(DiagCli, ModelOptionPredictsFromTheRealWrench) {
  // A linear sensor description with the fixture's own sensitivity: --model must reproduce its sim.
  const auto fx = testing::MakeFixture({{"zero_offset", 8}}, 6, 200.0, 1e-4, 1.0);
  WritePair(fx);
  const Eigen::MatrixXd s = sim::MakeDefaultSensor()->Sensitivity();
  nlohmann::json j{{"schema", "ftstack-sensor/1"}, {"name", "fixture"}};
  auto rows = nlohmann::json::array();
  for (int i = 0; i < s.rows(); ++i) {
    auto row = nlohmann::json::array();
    for (int k = 0; k < 6; ++k) row.push_back(s(i, k));
    rows.push_back(row);
  }
  j["model"] = {{"type", "linear"}, {"sensitivity_mvv", rows}};
  std::ofstream(P("sensor.json")) << j.dump();
  const CliRun r = Ftdiag("diagnose --model " + P("sensor.json") + " --real " + P("real.csv") +
                          " --json " + P("m.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(P("m.json"));
  const auto out = nlohmann::json::parse(in);
  EXPECT_EQ(out["verdict"], "zero_offset");
}

}  // namespace
}  // namespace ftstack::diag
