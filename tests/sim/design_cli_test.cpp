// `ftsim design` end to end: requirement verdict, the HTML report rendered in Chromium, the
// catalogue trend against an independent fit of the vendored CSV, and bad input.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "sim/design/explore.hpp"
#include "tests/support/chromium.hpp"
#include "tests/support/run_command.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim::design {
namespace {

using CliRun = test::CommandResult;

CliRun Ftsim(const std::string& args) {
  return test::RunCommand(std::string(FTSTACK_BIN_DIR) + "/ftsim design " + args);
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Independent fit: ln T = a + k ln F by QR on the design matrix, over rows whose 4th and 6th
/// CSV fields (Fxy_N, Txy_Nm) carry no '?'. Quoted fields only ever come last (source).
double IndependentExponent(bool confirmed_only, int* rows) {
  std::ifstream in(std::string(FTSTACK_SOURCE_DIR) + "/sim/design/data/ft_catalog.csv");
  std::string line;
  std::getline(in, line);
  std::vector<double> x, y;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    for (int i = 0; i < 7 && std::getline(ss, cell, ','); ++i) f.push_back(cell);
    if (f.size() < 6 || f[3].empty() || f[5].empty()) continue;
    const bool conf = f[3].back() != '?' && f[5].back() != '?';
    if (confirmed_only && !conf) continue;
    x.push_back(std::log(std::stod(f[3])));  // stod stops at a trailing '?'
    y.push_back(std::log(std::stod(f[5])));
  }
  Eigen::MatrixXd a(static_cast<Eigen::Index>(x.size()), 2);
  Eigen::VectorXd b(static_cast<Eigen::Index>(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i) {
    a(static_cast<Eigen::Index>(i), 0) = 1;
    a(static_cast<Eigen::Index>(i), 1) = x[i];
    b(static_cast<Eigen::Index>(i)) = y[i];
  }
  *rows = static_cast<int>(x.size());
  return a.colPivHouseholderQr().solve(b)(1);
}

TEST(DesignCli, PandaBaseReportMeetsItAndReproducesTheCatalogueTrend) {
  test::TempDir dir("design_cli");
  const std::string html = dir.path().string() + "/design.html";
  const CliRun run = Ftsim("--require panda-base --report " + html);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("Requirement panda-base (safety factor 1.50)"), std::string::npos);
  // The hub-and-spoke family cannot reach the goal and the verdict says why, in numbers.
  EXPECT_TRUE(
      std::regex_search(run.out, std::regex("hub-spoke: .*\\n.*lever Txy/Fxy .* 0\\.0[0-9]+ m")))
      << run.out;
  const std::string page = Slurp(html);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(page, m, std::regex("id='trend-exponent'>([0-9.]+)<")));
  int n = 0;
  const double k_confirmed = IndependentExponent(true, &n);
  EXPECT_GE(n, 10);
  EXPECT_NEAR(std::stod(m[1]), k_confirmed, 1e-3);
  int n_all = 0;
  const double k_all = IndependentExponent(false, &n_all);
  EXPECT_NEAR(k_all, 1.35, 0.1);  // the survey's stated trend
  EXPECT_NE(page.find(std::to_string(n_all) + " rows with values"), std::string::npos);
  EXPECT_EQ(page.find("http"), page.find("http://www.w3.org/2000/svg"));  // no network links
  if (!test::HaveChromium()) GTEST_SKIP() << "chromium not installed";
  const std::string png = dir.path().string() + "/design.png";
  ASSERT_TRUE(test::RenderWithChromium(html, png, dir.path().string() + "/chrome", 1200, 2400));
  EXPECT_GT(std::filesystem::file_size(png), 50000u);
}

TEST(DesignCli, BadRequirementIsRefusedWithItsPosition) {
  test::TempDir dir("design_cli");
  const std::string f = dir.path().string() + "/req.json";
  std::ofstream(f) << "{\"name\": \"x\",\n \"cases\": [[1, 2, 3, 4, 5, ]]}\n";
  const CliRun run = Ftsim("--require " + f);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find(f + ":2:"), std::string::npos) << run.out;
  const CliRun missing = Ftsim("--require " + dir.path().string() + "/none.json");
  EXPECT_EQ(missing.exit_code, 2);
}

TEST(DesignCli, SensorDescriptionIsEvaluated) {
  const CliRun run = Ftsim("--sensor builtin --tool-mass-kg 2");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("capacity alone"), std::string::npos);
  EXPECT_NE(run.out.find("rigid tool 2.00 kg"), std::string::npos);
}

// --eval FAMILY:key=value --json: every gauge printed and written in the documented order; the
// z-stage force gauge (row 0) against the guided-leaf hand formula (Fz/4 per leaf, S-bending:
// ε = (Fz/4)·(L/2 − s)·(t/2)/(E·I) at s = 0.1·L from the root; shear adds 0.3 % here).
TEST(DesignCli, EvalPrintsAndWritesEveryGauge) {
  test::TempDir dir("design_cli");
  const std::string json = dir.path().string() + "/d.json";
  const CliRun run = Ftsim(
      "--eval guided:leaf_length_m=0.04,leaf_width_m=0.03,leaf_thickness_z_m=0.0012,"
      "separation_m=0.06 --json " +
      json);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find(" 23  y moment, + side lower leaf, bottom"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("beam theory: every member is a slender beam"), std::string::npos);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("gauges").size(), 24u);
  EXPECT_EQ(j.at("gauges")[0].at("name"), "z force, + side upper leaf, top");
  const double e = 197e9, b = 0.03, t = 0.0012, l = 0.04, s = 0.1 * l;
  const double hand = 0.25 * (0.5 * l - s) * 0.5 * t / (e * b * t * t * t / 12);
  const double got = j.at("gauges")[0].at("strain_per_unit_wrench")[2].get<double>();
  EXPECT_NEAR(std::abs(got), hand, 0.02 * hand);
  const auto& k = j.at("stiffness_si");
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      const double a = k[r][c].get<double>(), bt = k[c][r].get<double>();
      EXPECT_NEAR(a, bt, 1e-6 * std::abs(k[r][r].get<double>()) + 1e-9) << r << "," << c;
    }
  }
  EXPECT_EQ(j.at("capacity").at("binding").size(), 6u);
  const CliRun bad = Ftsim("--eval guided:leaf_lenght_m=0.04");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.out.find("no parameter 'leaf_lenght_m'"), std::string::npos) << bad.out;
  const CliRun nan = Ftsim("--eval hub-spoke:beam_width_m=nan");
  EXPECT_EQ(nan.exit_code, 2);
  const CliRun missing = Ftsim("--eval H99999");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("no design H99999"), std::string::npos) << missing.out;
}

// --max-radius-m: no swept or refined design leaves the envelope.
TEST(DesignSweep, EnvelopeLimitHolds) {
  const Requirement req = LoadRequirement("panda-base");
  SweepOptions o;
  o.max_radius_m = 0.09;
  std::vector<Candidate> cs = Sweep(o, &req, nullptr);
  (void)RefineGuided(&cs, req, o, 2);
  ASSERT_GT(cs.size(), 100u);
  for (const Candidate& c : cs) {
    const auto& q = c.model.parameters;
    const double r = c.model.family == "guided" ? q.at("envelope_radius_m") : q.at("rim_radius_m");
    EXPECT_LE(r, 0.09 + 1e-12) << c.id;
  }
}

// The envelope maximum (sum of the groups' maxima) equals a brute-force search over directions.
TEST(DesignLoads, EnvelopeMaximumMatchesBruteForce) {
  const EnvelopeLoads env(300, 410, 280, 190);
  Row6 c;
  c << 1.0, -2.0, 0.5, 3.0, 1.5, -0.7;
  double brute = 0;
  for (int i = 0; i < 360; ++i) {
    for (int j = 0; j < 360; ++j) {
      const double a = i * M_PI / 180, b = j * M_PI / 180;
      for (double sz : {-1.0, 1.0}) {
        for (double sm : {-1.0, 1.0}) {
          Vec6 w;
          w << 300 * std::cos(a), 300 * std::sin(a), 410 * sz, 280 * std::cos(b), 280 * std::sin(b),
              190 * sm;
          brute = std::max(brute, std::abs(c.dot(w.transpose())));
        }
      }
    }
  }
  EXPECT_NEAR(env.Max(c), brute, 1e-3 * brute);
}

}  // namespace
}  // namespace ftstack::sim::design
