// `ftsim design --fe-check` against an independently written CalculiX model
// (tests/fe/independent_fe.py: its own geometry from the family parameters, gmsh's Python API,
// C3D20R under unit platform displacements, strains from surface displacements), the deck
// writer without ccx, the result readers on bad files, and the HTML report's FE section.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "sim/design/fe_deck.hpp"
#include "tests/support/chromium.hpp"
#include "tests/support/run_command.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim::design {
namespace {

using ShellRun = test::CommandResult;
ShellRun Shell(const std::string& cmd) { return test::RunCommand(cmd); }

bool HaveFe() {
  return Shell("command -v ccx && command -v gmsh && /usr/bin/python3 -c 'import gmsh, numpy'")
             .exit_code == 0;
}

const std::string kFtsim = std::string(FTSTACK_BIN_DIR) + "/ftsim design ";
// A small three-beam body (L/h = 3.5): seconds per mesh.
const std::string kSmall =
    "hub-spoke:beams=3,hub_radius_m=0.012,rim_radius_m=0.040,beam_width_m=0.006,beam_height_m="
    "0.008";

// The tool's FE check and the beam model against the independent solution: every stiffness
// diagonal term and every dominant gauge strain of the model within 10 %, the tool's own FE
// within 5 %; the HTML report carries the FE section and renders.
TEST(DesignFe, AgreesWithAnIndependentCalculixModel) {
  if (!HaveFe()) GTEST_SKIP() << "ccx, gmsh or python3-gmsh not installed";
  test::TempDir dir("design_fe");
  const std::string d = dir.path().string();
  const ShellRun tool =
      Shell(kFtsim + "--eval " + kSmall + " --fe-check --fe-size-m 0.004 --fe-dir " + d +
            "/fe --json " + d + "/design.json --report " + d + "/design.html");
  ASSERT_EQ(tool.exit_code, 0) << tool.out;
  EXPECT_NE(tool.out.find("FE mesh 2:"), std::string::npos) << tool.out;  // progress lines
  std::smatch m;
  ASSERT_TRUE(std::regex_search(tool.out, m, std::regex("largest \\|model/FE - 1\\|: ([0-9.]+)")));
  EXPECT_LT(std::stod(m[1]), 0.10) << tool.out;
  const ShellRun ind =
      Shell("/usr/bin/python3 " + std::string(FTSTACK_SOURCE_DIR) + "/tests/fe/independent_fe.py " +
            d + "/design.json " + d + "/ind --size-m 0.003 --out " + d + "/ind.json");
  ASSERT_EQ(ind.exit_code, 0) << ind.out;
  std::ifstream in(d + "/ind.json");
  const nlohmann::json r = nlohmann::json::parse(in);
  EXPECT_LT(r.at("worst_model").get<double>(), 0.10) << ind.out;
  EXPECT_LT(r.at("worst_tool").get<double>(), 0.05) << ind.out;
  int dominant_gauges = 0;
  for (const auto& row : r.at("rows")) {
    dominant_gauges += row.at("figure").get<std::string>().rfind("gauge", 0) == 0 ? 1 : 0;
  }
  EXPECT_GE(dominant_gauges, 12);  // the check covers the bridges, not only the stiffness
  std::ifstream html_in(d + "/design.html");
  std::stringstream html;
  html << html_in.rdbuf();
  EXPECT_NE(html.str().find("FE check of eval"), std::string::npos);
  EXPECT_NE(html.str().find("Timoshenko frame model"), std::string::npos);
  EXPECT_NE(html.str().find("id='fe-worst'"), std::string::npos);
  if (!test::HaveChromium()) GTEST_SKIP() << "chromium not installed";
  const std::string png = d + "/design.png";
  ASSERT_TRUE(test::RenderWithChromium(d + "/design.html", png, d + "/chrome", 1200, 3000));
  EXPECT_GT(std::filesystem::file_size(png), 50000u);
}

// Without ccx on the PATH the deck is still written and the output says how to run it.
TEST(DesignFe, WithoutCcxWritesTheDeckAndSaysHowToRunIt) {
  if (Shell("command -v gmsh").exit_code != 0) GTEST_SKIP() << "gmsh not installed";
  test::TempDir dir("design_fe_deck");
  const std::string d = dir.path().string();
  std::filesystem::create_directories(d + "/bin");
  const std::string gmsh = Shell("command -v gmsh").out;
  std::filesystem::create_symlink(gmsh.substr(0, gmsh.find('\n')), d + "/bin/gmsh");
  const ShellRun run = Shell("PATH=" + d + "/bin " + kFtsim + "--eval " + kSmall +
                             " --fe-check --fe-size-m 0.008 --fe-dir " + d + "/fe");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("ccx is not installed"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("ccx -i deck"), std::string::npos) << run.out;
  std::ifstream deck(d + "/fe/mesh2/deck.inp");
  std::stringstream text;
  text << deck.rdbuf();
  EXPECT_NE(text.str().find("*RIGID BODY,NSET=B1"), std::string::npos);
  EXPECT_NE(text.str().find("*CLOAD,OP=NEW"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(d + "/fe/mesh1/body.geo"));
}

// Result files that stop early or hold garbage are refused with file and line.
TEST(DesignFe, ReadersRefuseBadResultFiles) {
  std::istringstream dat(
      " displacements (vx,vy,vz) for set PLATFORM and time  0.1E+01\n\n 101 1.0E-06 0 0\n");
  try {
    (void)ReadPlatformCompliance(dat, 101, "deck.dat");
    FAIL() << "a one-step file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("deck.dat:3: fewer than six steps"), std::string::npos)
        << e.what();
  }
  std::istringstream inp("*NODE\n1, 0, 0, 0\n2, 0, x, 0\n");
  try {
    (void)ReadInpNodes(inp, "mesh.inp");
    FAIL() << "a bad node line was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.inp:3:"), std::string::npos) << e.what();
  }
  std::istringstream frd(" -4  TOSTRAIN    6    1\n -1         1 1.00000E-06 nan\n -3\n");
  try {
    (void)ReadFrdBlocks(frd, "TOSTRAIN", "deck.frd");
    FAIL() << "a NaN strain was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("deck.frd:2:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ftstack::sim::design
