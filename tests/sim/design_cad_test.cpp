// `ftsim design --step/--stl` (the body as drawn through gmsh's OpenCASCADE kernel) read back by
// an independent reader in a separate process (tests/fe/read_step.py on Debian's python3-gmsh):
// one solid, its volume against a closed form from the design's dimensions, every gauge site on
// the solid's surface at its imprinted pad; the STL's enclosed volume; bad requests refused.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "tests/support/run_command.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack {
namespace {

constexpr double kPi = std::numbers::pi;
const std::string kFtsim = std::string(FTSTACK_BIN_DIR) + "/ftsim design ";
const std::string kReader =
    "/usr/bin/python3 " + std::string(FTSTACK_SOURCE_DIR) + "/tests/fe/read_step.py ";

bool HaveReader() { return test::RunCommand("/usr/bin/python3 -c 'import gmsh'").exit_code == 0; }

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

/// ∫_{-a}^{a} √(R² − y²) dy: a chord strip of a disk.
double Strip(double r, double a) { return a * std::sqrt(r * r - a * a) + r * r * std::asin(a / r); }

/// The hub-spoke drawing (docs/design.md, sim/design/body_cad.hpp): hub disk, beams between the
/// hub and rim circles, rim ring max(w, h) wide, all h deep; per beam a hub hole Ø 0.3·hub
/// radius and a rim hole Ø 0.4·rim width, through.
double HubSpokeVolumeM3(const nlohmann::json& p) {
  const double rh = p.at("hub_radius_m"), rr = p.at("rim_radius_m");
  const double w = p.at("beam_width_m"), h = p.at("beam_height_m");
  const int n = static_cast<int>(p.at("beams").get<double>());
  const double rw = std::max(w, h);
  const double solid = kPi * rh * rh + n * (Strip(rr, 0.5 * w) - Strip(rh, 0.5 * w)) +
                       kPi * ((rr + rw) * (rr + rw) - rr * rr);
  const double holes = n * kPi * (std::pow(0.15 * rh, 2) + std::pow(0.2 * rw, 2));
  return h * (solid - holes);
}

/// The guided drawing: 12 leaves, a platform block between the z stage's inner roots, three
/// rectangular frames of plates e = max(b/4, 3 t) thick (two end and two side plates each), two
/// platform holes Ø min(inner radius, b)/4 and four ground holes Ø e/2 through the end plates.
double GuidedVolumeM3(const nlohmann::json& p) {
  const double len = p.at("leaf_length_m"), b = p.at("leaf_width_m");
  const double t = p.at("leaf_thickness_m"), tz = p.at("leaf_thickness_z_m");
  const double d = p.at("separation_m"), c0 = p.at("inner_radius_m");
  const double gap = 0.5 * (p.at("envelope_radius_m").get<double>() - c0 - 3 * len);
  const double c1 = c0 + len + gap, c2 = c1 + len + gap,
               e = std::max(0.25 * b, 3 * std::max(t, tz));
  const double z2 = std::max(0.5 * (d + tz), 0.5 * b), x3 = std::max(0.5 * (d + t), 0.5 * b);
  const double y0 = c1 + len + 2 * e + gap, ph = 0.25 * std::min(c0, b);
  const auto frame = [e](double u_in, double v_half, double a_half) {
    return 2 * e * 2 * v_half * 2 * a_half + 2 * e * 2 * u_in * 2 * a_half;
  };
  return 2 * c0 * b * 2 * z2 - 2 * kPi * 0.25 * ph * ph * 2 * z2 + 4 * len * b * tz +
         8 * len * b * t + frame(c0 + len, c1, z2) + frame(c1 + len, c2, x3) +
         frame(c2 + len, y0, x3) - 4 * kPi * std::pow(0.25 * e, 2) * e;
}

/// Volume enclosed by an ASCII STL (divergence theorem over its triangles), in the file's unit.
double StlVolume(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  std::vector<double> v;
  double vol = 0;
  while (in >> word) {
    if (word != "vertex") continue;
    for (int k = 0; k < 3; ++k) v.push_back(0), in >> v.back();
    if (v.size() == 9) {
      vol += (v[0] * (v[4] * v[8] - v[5] * v[7]) - v[1] * (v[3] * v[8] - v[5] * v[6]) +
              v[2] * (v[3] * v[7] - v[4] * v[6])) /
             6.0;
      v.clear();
    }
  }
  return std::abs(vol);
}

struct Case {
  const char* name;
  std::string args;
};

class DesignCad : public ::testing::TestWithParam<Case> {};

TEST_P(DesignCad, StepReadBackIsTheDrawnBodyWithItsGaugeSites) {
  if (!HaveReader()) GTEST_SKIP() << "python3-gmsh not installed";
  test::TempDir dir("design_cad");
  const std::string d = dir.path().string();
  const auto tool =
      test::RunCommand(kFtsim + GetParam().args + " --step " + d + "/body.step --stl " + d +
                       "/body.stl --json " + d + "/design.json");
  ASSERT_EQ(tool.exit_code, 0) << tool.out;
  EXPECT_NE(tool.out.find("Body as drawn"), std::string::npos) << tool.out;
  const nlohmann::json design = ReadJson(d + "/design.json");
  const nlohmann::json& p = design.at("parameters");
  const double expected_mm3 =
      1e9 * (design.at("family") == "guided" ? GuidedVolumeM3(p) : HubSpokeVolumeM3(p));

  // Query points: every gauge site as the report gives it, and (as a control that the reader
  // can say "not on the surface") each site 0.5 mm outside along its normal.
  nlohmann::json points = nlohmann::json::array();
  const auto& gauges = design.at("gauges");
  for (int shift = 0; shift < 2; ++shift) {
    for (const auto& g : gauges) {
      nlohmann::json q = {{"normal", g.at("normal")}, {"point_mm", nlohmann::json::array()}};
      for (int k = 0; k < 3; ++k) {
        q["point_mm"].push_back(1e3 * g.at("point_m")[k].get<double>() +
                                0.5 * shift * g.at("normal")[k].get<double>());
      }
      points.push_back(q);
    }
  }
  std::ofstream(d + "/points.json") << points.dump();
  const auto read =
      test::RunCommand(kReader + d + "/body.step " + d + "/points.json " + d + "/read.json");
  ASSERT_EQ(read.exit_code, 0) << read.out;
  const nlohmann::json r = ReadJson(d + "/read.json");
  EXPECT_EQ(r.at("solids").get<int>(), 1);
  EXPECT_NEAR(r.at("volume_mm3").get<double>() / expected_mm3, 1.0, 0.01);
  const double pad_m = design.at("cad").at("gauge_pad_m");
  const std::size_t g_count = gauges.size();
  ASSERT_GT(g_count, 0U);
  for (std::size_t i = 0; i < r.at("points").size(); ++i) {
    const auto& q = r.at("points")[i];
    if (i < g_count) {
      SCOPED_TRACE(gauges[i].at("name").get<std::string>());
      ASSERT_TRUE(q.at("surface_distance_mm").is_number()) << "no face through the site";
      EXPECT_LT(q.at("surface_distance_mm").get<double>(), 1e-6);
      EXPECT_TRUE(q.at("normal_parallel").get<bool>());
      EXPECT_LT(q.at("pad_centre_distance_mm").get<double>(), 1e-6);  // the pad marks the site
      EXPECT_NEAR(q.at("pad_area_mm2").get<double>(), 1e6 * pad_m * pad_m, 1e-6);
    } else {
      EXPECT_TRUE(q.at("surface_distance_mm").is_null()) << q.dump();  // no face through it
    }
  }
  // The STL: a faceted surface of the same solid (cylinders as polygons: within 2 %).
  EXPECT_NEAR(StlVolume(d + "/body.stl") / expected_mm3, 1.0, 0.02);
}

INSTANTIATE_TEST_SUITE_P(
    ThreeBodies, DesignCad,
    ::testing::Values(
        Case{"HubSpokeDefault", "--eval hub-spoke:"},
        Case{"ProjectDefaultBody",
             "--sensor " + std::string(FTSTACK_SOURCE_DIR) + "/sim/sensors/default.json"},
        // The Panda-base winner R02 (docs/design.md), by its parameters.
        Case{"PandaWinnerR02",
             "--eval guided:inner_radius_m=0.02,leaf_length_m=0.068012,leaf_thickness_m="
             "0.00151176,leaf_thickness_z_m=0.00158489,leaf_width_m=0.0381453,separation_m="
             "0.118585"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(DesignCadCli, StlWithoutStepAndUndrawableLayoutsAreRefused) {
  test::TempDir dir("design_cad_cli");
  const std::string d = dir.path().string();
  const auto stl_only = test::RunCommand(kFtsim + "--eval hub-spoke: --stl " + d + "/b.stl");
  EXPECT_NE(stl_only.exit_code, 0);
  EXPECT_NE(stl_only.out.find("needs --step"), std::string::npos) << stl_only.out;
  // Beams 30 mm wide on a 10 mm hub overlap each other at the hub: no drawing, a reason.
  const auto overlap = test::RunCommand(
      kFtsim + "--eval hub-spoke:hub_radius_m=0.01,beam_width_m=0.03 --step " + d + "/b.step");
  EXPECT_NE(overlap.exit_code, 0);
  EXPECT_NE(overlap.out.find("overlap at the hub"), std::string::npos) << overlap.out;
}

}  // namespace
}  // namespace ftstack
