// `ftsim record` as a program: files written per the recording format, one-line errors on bad
// input.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "measurement/recording.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

struct ProgramRun {
  int status = -1;
  std::string err;
};

ProgramRun Ftsim(const std::string& args) {
  const std::string err_path = ftstack::test::ProcessTempDir() + "/ftsim_record_stderr.txt";
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/ftsim record " + args + " 2>" + err_path;
  ProgramRun r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(err_path);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

TEST(FtsimRecordCli, WritesRealSimAndTruth) {
  const std::string d = ftstack::test::ProcessTempDir();
  const ProgramRun r = Ftsim("--profile taps --duration-s 3 --seed 2 --out " + d +
                             "/r.csv --sim-out " + d + "/s.csv --truth " + d +
                             "/t.json --effect creep:tau_s=5 --effect 'zero_offset:channels=[1]'");
  ASSERT_EQ(r.status, 0) << r.err;
  ftstack::ReadOptions opt;
  opt.require_wrench = true;
  opt.require_bridges = true;
  const auto real = ftstack::ReadRecording(d + "/r.csv", opt);
  const auto sim = ftstack::ReadRecording(d + "/s.csv", opt);
  EXPECT_EQ(real.rows(), 601u);  // 3 s at the taps profile's 200 Hz, both ends included
  EXPECT_EQ(real.BridgeCount(), 6u);
  EXPECT_TRUE(real.Has("temp_C"));
  EXPECT_NO_THROW(ftstack::CheckAligned(sim, real));
  std::ifstream tj(d + "/t.json");
  const auto truth = nlohmann::json::parse(tj);
  ASSERT_EQ(truth["effects"].size(), 2u);
  EXPECT_EQ(truth["effects"][0]["name"], "creep");
  EXPECT_DOUBLE_EQ(truth["effects"][0]["params"]["tau_s"].get<double>(), 5.0);
  EXPECT_EQ(truth["effects"][1]["params"]["channels"], nlohmann::json::array({1}));

  ASSERT_EQ(Ftsim("--profile taps --duration-s 1 --no-temp --out " + d + "/n.csv").status, 0);
  EXPECT_FALSE(ftstack::ReadRecording(d + "/n.csv").Has("temp_C"));
}

TEST(FtsimRecordCli, BadInputGivesOneLineReason) {
  const std::string out = " --duration-s 1 --out " + ftstack::test::ProcessTempDir() + "/x.csv";
  const struct {
    std::string args;
    std::string message;
  } cases[] = {
      {"--effect bogus", "ftsim record: --effect 'bogus': unknown effect 'bogus'"},
      {"--effect creep:tau_s=inf",
       "ftsim record: --effect 'creep:tau_s=inf': tau_s='inf' is not a finite number"},
      {"--effect creep:speed=2", "unknown key 'speed' for creep"},
      {"--effect gain_error:channels=7", "channel 7 does not exist"},
      {"--profile nowhere.json", "nowhere.json: cannot open profile"},
      {"--noise-mvv nan", "--noise-mvv must be a finite number"},
      {"--sensor nowhere-sensor.json", "nowhere-sensor.json"},
  };
  for (const auto& c : cases) {
    const ProgramRun r = Ftsim(c.args + out);
    EXPECT_NE(r.status, 0) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << " → " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
