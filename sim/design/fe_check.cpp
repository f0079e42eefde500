#include "sim/design/fe_check.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "measurement/wrench.hpp"

namespace ftstack::sim::design {
namespace {

namespace fs = std::filesystem;

bool Installed(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

void RunOrThrow(const std::string& cmd, const std::string& what, const fs::path& log) {
  if (std::system((cmd + " > " + Quote(log.string()) + " 2>&1").c_str()) != 0) {
    throw std::runtime_error(what + " failed; see " + log.string());
  }
}

std::ifstream OpenIn(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  return in;
}

double Ratio(double model, double fe) { return fe != 0 ? model / fe : NAN; }

}  // namespace

FeCheck RunFeCheck(const DesignModel& m, const FeCheckOptions& o, std::ostream* progress) {
  if (m.members.empty()) throw std::invalid_argument("fe check: the design has no solid members");
  FeCheck c;
  c.model_stiffness = m.stiffness;
  c.model_gauge_strain = m.gauge_strain;
  for (const GaugeGrid& g : m.gauges) c.gauge_names.push_back(g.name);
  for (int k = 0; k < 6; ++k) {
    const double top = m.gauge_strain.col(k).cwiseAbs().maxCoeff();
    for (Eigen::Index g = 0; g < m.gauge_strain.rows(); ++g) {
      if (top > 0 && std::abs(m.gauge_strain(g, k)) >= 0.25 * top) {
        c.dominant.emplace_back(static_cast<int>(g), k);
      }
    }
  }
  double size = o.element_size_m;
  if (!(size > 0)) {
    size = INFINITY;
    for (const SolidMember& mb : m.members) size = std::min(size, (mb.b_m - mb.a_m).norm() / 8);
  }
  fs::create_directories(o.work_dir);
  const bool have_gmsh = Installed("gmsh"), have_ccx = Installed("ccx");
  for (int level = 0; level < 2; ++level) {
    FeMeshSize ms{size / (level == 0 ? 1.0 : o.refinement), o.min_layers + level};
    const fs::path dir = fs::path(o.work_dir) / (level == 0 ? "mesh1" : "mesh2");
    fs::create_directories(dir);
    {
      std::ofstream geo(dir / "body.geo");
      WriteGmshGeometry(geo, m, ms);
      if (!geo) throw std::runtime_error("cannot write " + (dir / "body.geo").string());
    }
    if (!have_gmsh) {
      c.note = "gmsh is not installed: wrote " + (dir / "body.geo").string() +
               " only (apt-get install gmsh calculix-ccx, then run --fe-check again)";
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (progress != nullptr) {
      *progress << fmt::format("  FE mesh {}: element size {:.3g} mm, {} layers: meshing…\n",
                               level + 1, 1e3 * ms.element_size_m, ms.min_layers)
                << std::flush;
    }
    RunOrThrow(
        "cd " + Quote(dir.string()) + " && gmsh body.geo -3 -order 2 -format inp -o mesh.inp",
        "gmsh", dir / "gmsh.log");
    std::ifstream mesh_in = OpenIn(dir / "mesh.inp");
    const auto nodes = ReadInpNodes(mesh_in, (dir / "mesh.inp").string());
    {
      std::ofstream deck(dir / "deck.inp");
      WriteCalculixDeck(deck, m, nodes, "mesh.inp");
      if (!deck) throw std::runtime_error("cannot write " + (dir / "deck.inp").string());
    }
    if (!have_ccx || !o.run) {
      c.note = fmt::format(
          "{} wrote {}; solve with: cd {} && ccx -i deck (platform compliance in deck.dat, "
          "strains in deck.frd)",
          have_ccx ? "" : "ccx is not installed:", (dir / "deck.inp").string(), dir.string());
      continue;
    }
    if (progress != nullptr) {
      *progress << fmt::format("  FE mesh {}: {} nodes, solving six load cases with ccx…\n",
                               level + 1, nodes.size())
                << std::flush;
    }
    RunOrThrow("cd " + Quote(dir.string()) + " && ccx -i deck", "ccx", dir / "ccx.log");
    FeSolution s;
    s.element_size_m = ms.element_size_m;
    s.layers = ms.min_layers;
    s.nodes = static_cast<int>(nodes.size());
    std::ifstream dat = OpenIn(dir / "deck.dat");
    const Mat6 compliance =
        ReadPlatformCompliance(dat, RefNode(1, nodes.rbegin()->first), (dir / "deck.dat").string());
    s.stiffness = (0.5 * (compliance + compliance.transpose())).inverse();
    std::ifstream frd = OpenIn(dir / "deck.frd");
    const auto strain = ReadFrdBlocks(frd, "TOSTRAIN", (dir / "deck.frd").string());
    s.gauge_strain = GaugeStrainFromNodes(m, nodes, strain, o.fit_nodes);
    std::ifstream frd2 = OpenIn(dir / "deck.frd");
    const auto disp = ReadFrdBlocks(frd2, "DISP", (dir / "deck.frd").string());
    const std::size_t every = std::max<std::size_t>(1, nodes.size() / 3000);
    std::size_t i = 0;
    for (const auto& [id, p] : nodes) {
      const auto u = disp.size() > 2 ? disp[2].find(id) : disp.front().end();
      const auto e = strain[2].find(id);
      if (i++ % every != 0 || disp.size() <= 2 || u == disp[2].end() || e == strain[2].end() ||
          u->second.size() < 3 || e->second.size() < 6) {
        continue;
      }
      s.sample_m.push_back(p);
      s.sample_u.emplace_back(u->second[0], u->second[1], u->second[2]);
      const std::vector<double>& t = e->second;
      s.sample_strain.push_back(std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2] +
                                          2 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])));
    }
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c.meshes.push_back(s);
    c.ran = true;
    c.note = "solved with ccx in " + o.work_dir;
  }
  return c;
}

double WorstFeDeviation(const FeCheck& c) {
  if (c.meshes.empty()) return NAN;
  const FeSolution& fe = c.meshes.back();
  double worst = 0;
  for (int k = 0; k < 6; ++k) {
    worst = std::max(worst, std::abs(Ratio(c.model_stiffness(k, k), fe.stiffness(k, k)) - 1));
  }
  for (const auto& [g, k] : c.dominant) {
    worst = std::max(worst, std::abs(Ratio(c.model_gauge_strain(g, k), fe.gauge_strain(g, k)) - 1));
  }
  return worst;
}

void PrintFeCheck(std::ostream& out, const FeCheck& c) {
  out << "FE check (solid C3D20, gmsh + CalculiX; idealisations as the beam model: member ends "
         "clamped to rigid bodies): "
      << c.note << "\n";
  if (c.meshes.empty()) return;
  for (std::size_t i = 0; i < c.meshes.size(); ++i) {
    const FeSolution& s = c.meshes[i];
    out << fmt::format("  mesh {}: element size {:.3g} mm, {} layers, {} nodes, {:.1f} s\n", i + 1,
                       1e3 * s.element_size_m, s.layers, s.nodes, s.seconds);
  }
  const FeSolution& fe = c.meshes.back();
  const FeSolution& first = c.meshes.front();
  out << "  stiffness diagonal         model          FE   model/FE   mesh1/mesh2\n";
  for (int k = 0; k < 6; ++k) {
    out << fmt::format("    K{}{} {:>9}  {:11.4g} {:11.4g}   {:8.3f}   {:8.4f}\n",
                       kWrenchAxisNames[k], kWrenchAxisNames[k], k < 3 ? "N/m" : "N·m/rad",
                       c.model_stiffness(k, k), fe.stiffness(k, k),
                       Ratio(c.model_stiffness(k, k), fe.stiffness(k, k)),
                       Ratio(first.stiffness(k, k), fe.stiffness(k, k)));
  }
  out << "  dominant gauge strains (µε per N or N·m)    model          FE   model/FE   "
         "mesh1/mesh2\n";
  for (const auto& [g, k] : c.dominant) {
    out << fmt::format("    {:3d} {:<34} {} {:11.4g} {:11.4g}   {:8.3f}   {:8.4f}\n", g,
                       c.gauge_names[static_cast<std::size_t>(g)], kWrenchAxisNames[k],
                       1e6 * c.model_gauge_strain(g, k), 1e6 * fe.gauge_strain(g, k),
                       Ratio(c.model_gauge_strain(g, k), fe.gauge_strain(g, k)),
                       Ratio(first.gauge_strain(g, k), fe.gauge_strain(g, k)));
  }
  out << fmt::format("  largest |model/FE - 1|: {:.3f}\n", WorstFeDeviation(c));
}

nlohmann::json FeCheckJson(const FeCheck& c) {
  nlohmann::json j;
  j["ran"] = c.ran;
  j["note"] = c.note;
  nlohmann::json meshes = nlohmann::json::array();
  for (const FeSolution& s : c.meshes) {
    nlohmann::json mj;
    mj["element_size_m"] = s.element_size_m;
    mj["layers"] = s.layers;
    mj["nodes"] = s.nodes;
    mj["seconds"] = s.seconds;
    std::vector<double> diag;
    for (int k = 0; k < 6; ++k) diag.push_back(s.stiffness(k, k));
    mj["stiffness_diagonal_si"] = diag;
    nlohmann::json rows = nlohmann::json::array();
    for (int i = 0; i < 6; ++i) {
      rows.push_back({s.stiffness(i, 0), s.stiffness(i, 1), s.stiffness(i, 2), s.stiffness(i, 3),
                      s.stiffness(i, 4), s.stiffness(i, 5)});
    }
    mj["stiffness_si"] = rows;
    nlohmann::json dom = nlohmann::json::array();
    for (const auto& [g, k] : c.dominant) {
      dom.push_back(
          {{"gauge", g}, {"axis", kWrenchAxisNames[k]}, {"strain", s.gauge_strain(g, k)}});
    }
    mj["dominant_strain_per_unit_wrench"] = dom;
    meshes.push_back(mj);
  }
  j["meshes"] = meshes;
  std::vector<double> diag;
  for (int k = 0; k < 6; ++k) diag.push_back(c.model_stiffness(k, k));
  j["model_stiffness_diagonal_si"] = diag;
  nlohmann::json dom = nlohmann::json::array();
  for (const auto& [g, k] : c.dominant) {
    dom.push_back({{"gauge", g},
                   {"name", c.gauge_names[static_cast<std::size_t>(g)]},
                   {"axis", kWrenchAxisNames[k]},
                   {"strain", c.model_gauge_strain(g, k)}});
  }
  j["model_dominant_strain_per_unit_wrench"] = dom;
  j["worst_deviation"] =
      c.meshes.empty() ? nlohmann::json(nullptr) : nlohmann::json(WorstFeDeviation(c));
  return j;
}

}  // namespace ftstack::sim::design
