#include "sim/design/fe_deck.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace ftstack::sim::design {
namespace {

struct MemberFrame {
  Eigen::Vector3d x, y, z;
  double length = 0;
};

MemberFrame FrameOf(const SolidMember& m) {
  MemberFrame f;
  f.length = (m.b_m - m.a_m).norm();
  if (!(f.length > 0)) throw std::invalid_argument("fe model: a member has zero length");
  f.x = (m.b_m - m.a_m) / f.length;
  f.z = (m.z_axis - m.z_axis.dot(f.x) * f.x).normalized();
  f.y = f.z.cross(f.x);
  return f;
}

[[noreturn]] void Fail(const std::string& origin, int line, const std::string& what) {
  throw std::runtime_error(fmt::format("{}:{}: {}", origin, line, what));
}

void WriteSet(std::ostream& out, const std::string& name, const std::vector<int>& ids) {
  out << "*NSET,NSET=" << name << "\n";
  for (std::size_t i = 0; i < ids.size(); ++i) {
    out << ids[i] << (i + 1 == ids.size() || i % 10 == 9 ? ",\n" : ", ");
  }
}

/// Rigid bodies of the member ends: a member with a released end b gets a body of its own there
/// (numbered after the model's), held to the ground by springs. Returns {body_a, body_b} per
/// member and sets *count to the number of bodies.
std::vector<std::array<int, 2>> EndBodies(const DesignModel& m, int* count) {
  std::vector<std::array<int, 2>> out;
  int next = m.body_count;
  for (const SolidMember& mb : m.members) {
    const bool released = std::any_of(mb.end_b_compliance.begin(), mb.end_b_compliance.end(),
                                      [](double c) { return c > 0; });
    if (released && mb.body_b != kGround) {
      throw std::invalid_argument("fe model: releases are modelled only towards the ground");
    }
    for (int k = 3; k < 6; ++k) {
      if (mb.end_b_compliance[static_cast<std::size_t>(k)] > 0) {
        throw std::invalid_argument("fe model: rotational end releases are not modelled");
      }
    }
    out.push_back({mb.body_a, released ? next++ : mb.body_b});
  }
  *count = next;
  return out;
}

}  // namespace

std::array<int, 3> MemberDivisions(const SolidMember& m, const FeMeshSize& s) {
  if (!(s.element_size_m > 0) || s.min_layers < 1) {
    throw std::invalid_argument("fe model: element size must be > 0 and layers >= 1");
  }
  auto n = [&](double len, int lo) {
    return std::max(lo, static_cast<int>(std::ceil(len / s.element_size_m - 1e-9)));
  };
  return {n((m.b_m - m.a_m).norm(), 4), n(m.width_m, s.min_layers), n(m.height_m, s.min_layers)};
}

void WriteGmshGeometry(std::ostream& out, const DesignModel& m, const FeMeshSize& s) {
  out << "// " << m.family << " body for a solid FE check (m); members are boxes extruded from\n"
      << "// their end section, meshed with structured 20-node hexahedra.\n"
      << "Mesh.ElementOrder = 2;\nMesh.SecondOrderIncomplete = 1;\n";
  std::string volumes;
  for (std::size_t i = 0; i < m.members.size(); ++i) {
    const SolidMember& mb = m.members[i];
    const MemberFrame f = FrameOf(mb);
    const auto div = MemberDivisions(mb, s);
    const double hw = 0.5 * mb.width_m, hh = 0.5 * mb.height_m;
    const Eigen::Vector3d c[4] = {mb.a_m - hw * f.y - hh * f.z, mb.a_m + hw * f.y - hh * f.z,
                                  mb.a_m + hw * f.y + hh * f.z, mb.a_m - hw * f.y + hh * f.z};
    // Tags from newp/newl/news: an extrusion creates entities of its own.
    out << fmt::format("p{0} = newp;\n", i);
    for (int k = 0; k < 4; ++k) {
      out << fmt::format("Point(p{} + {}) = {{{:.12g}, {:.12g}, {:.12g}}};\n", i, k, c[k].x(),
                         c[k].y(), c[k].z());
    }
    out << fmt::format("l{0} = newl;\n", i);
    for (int k = 0; k < 4; ++k) {
      out << fmt::format("Line(l{0} + {1}) = {{p{0} + {1}, p{0} + {2}}};\n", i, k, (k + 1) % 4);
    }
    const Eigen::Vector3d d = f.length * f.x;
    out << fmt::format(
        "s{0} = news;\nCurve Loop(s{0}) = {{l{0}, l{0} + 1, l{0} + 2, l{0} + 3}};\n"
        "Plane Surface(s{0}) = {{s{0}}};\n"
        "Transfinite Curve{{l{0}, l{0} + 2}} = {1};\nTransfinite Curve{{l{0} + 1, l{0} + 3}} = "
        "{2};\n"
        "Transfinite Surface{{s{0}}};\nRecombine Surface{{s{0}}};\n"
        "v{0}[] = Extrude {{{3:.12g}, {4:.12g}, {5:.12g}}} {{ Surface{{s{0}}}; Layers{{{6}}}; "
        "Recombine; }};\n",
        i, div[1] + 1, div[2] + 1, d.x(), d.y(), d.z(), div[0]);
    volumes += fmt::format("{}v{}[1]", volumes.empty() ? "" : ", ", i);
  }
  out << "Physical Volume(\"BODY\") = {" << volumes << "};\n";
}

std::map<int, Eigen::Vector3d> ReadInpNodes(std::istream& in, const std::string& origin) {
  std::map<int, Eigen::Vector3d> nodes;
  std::string line;
  int n = 0;
  bool in_nodes = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line[0] == '*') {
      std::string key = line;
      std::transform(key.begin(), key.end(), key.begin(), ::toupper);
      in_nodes = key.rfind("*NODE", 0) == 0 && key.find("PRINT") == std::string::npos &&
                 key.find("FILE") == std::string::npos;
      continue;
    }
    if (!in_nodes || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::stringstream ss(line);
    int id = 0;
    char comma = 0;
    double x = NAN, y = NAN, z = NAN;
    if (!(ss >> id >> comma >> x >> comma >> y >> comma >> z) || !std::isfinite(x + y + z)) {
      Fail(origin, n, "a node line is not 'id, x, y, z'");
    }
    nodes[id] = Eigen::Vector3d(x, y, z);
  }
  if (nodes.empty()) Fail(origin, n, "no *NODE block");
  return nodes;
}

int RefNode(int body, int max_mesh_node) { return max_mesh_node + 10 * body + 1; }

namespace {

/// A released end's body: rotation held, each member-local translation either held (an
/// *EQUATION along that axis) or on a SPRINGA to a fixed anchor along it (stiffness 1/compliance).
void WriteReleases(std::ostream& out, const DesignModel& m,
                   const std::vector<std::array<int, 2>>& ends, int top) {
  int element = 2 * top + 10;  // above every element id of the mesh (fewer elements than nodes)
  for (std::size_t i = 0; i < m.members.size(); ++i) {
    const int body = ends[i][1];
    if (body < m.body_count) continue;
    const int ref = RefNode(body, top);
    const MemberFrame f = FrameOf(m.members[i]);
    const Eigen::Vector3d axes[3] = {f.x, f.y, f.z};
    out << fmt::format("*BOUNDARY\n{}, 1, 3\n", ref + 1);
    std::array<bool, 3> dependent{};
    for (int k = 0; k < 3; ++k) {
      const double c = m.members[i].end_b_compliance[static_cast<std::size_t>(k)];
      if (c > 0) {
        out << fmt::format(
            "*BOUNDARY\n{0}, 1, 3\n*ELEMENT,TYPE=SPRINGA,ELSET=R{1}_{2}\n{3}, {4}, {0}\n"
            "*SPRING,ELSET=R{1}_{2}\n\n{5:.9e}\n",
            ref + 2 + k, body, k, element++, ref, 1.0 / c);
        continue;
      }
      // Held: a·u = 0, the dependent term the largest coefficient not yet dependent.
      int lead = -1;
      for (int j = 0; j < 3; ++j) {
        if (!dependent[static_cast<std::size_t>(j)] && std::abs(axes[k](j)) > 1e-9 &&
            (lead < 0 || std::abs(axes[k](j)) > std::abs(axes[k](lead)))) {
          lead = j;
        }
      }
      if (lead < 0) throw std::invalid_argument("fe model: cannot hold a released end");
      dependent[static_cast<std::size_t>(lead)] = true;
      std::string terms = fmt::format("{}, {}, {:.12g}", ref, lead + 1, axes[k](lead));
      int n = 1;
      for (int j = 0; j < 3; ++j) {
        if (j == lead || std::abs(axes[k](j)) <= 1e-12) continue;
        terms += fmt::format(", {}, {}, {:.12g}", ref, j + 1, axes[k](j));
        ++n;
      }
      out << "*EQUATION\n" << n << "\n" << terms << "\n";
    }
  }
}

}  // namespace

std::vector<std::vector<int>> EndFaceNodes(const DesignModel& m,
                                           const std::map<int, Eigen::Vector3d>& nodes) {
  int count = 0;
  const auto ends = EndBodies(m, &count);
  std::vector<std::vector<int>> faces(static_cast<std::size_t>(count));
  std::vector<MemberFrame> frames;
  for (const SolidMember& mb : m.members) frames.push_back(FrameOf(mb));
  for (const auto& [id, p] : nodes) {
    int owner = -1;
    for (std::size_t i = 0; i < m.members.size(); ++i) {
      const SolidMember& mb = m.members[i];
      const MemberFrame& f = frames[i];
      const Eigen::Vector3d r = p - mb.a_m;
      const double tol = 1e-7 * f.length;
      if (std::abs(r.dot(f.y)) > 0.5 * mb.width_m + tol ||
          std::abs(r.dot(f.z)) > 0.5 * mb.height_m + tol) {
        continue;
      }
      const double s = r.dot(f.x);
      const int body =
          std::abs(s) < tol ? ends[i][0] : (std::abs(s - f.length) < tol ? ends[i][1] : -1);
      if (body < 0) continue;
      if (owner >= 0 && owner != body) {
        throw std::invalid_argument("fe model: members of different bodies touch at node " +
                                    std::to_string(id));
      }
      owner = body;
    }
    if (owner >= 0) faces[static_cast<std::size_t>(owner)].push_back(id);
  }
  return faces;
}

void WriteCalculixDeck(std::ostream& out, const DesignModel& m,
                       const std::map<int, Eigen::Vector3d>& nodes, const std::string& mesh_file) {
  const int top = nodes.rbegin()->first;
  const std::vector<std::vector<int>> faces = EndFaceNodes(m, nodes);
  out << "** Solid FE check of " << m.family << " design " << m.name
      << " (SI units: m, N, Pa). Written by ftsim design --fe-check.\n"
      << "** Idealisations as the beam model: member ends clamped to rigid bodies.\n"
      << "*INCLUDE,INPUT=" << mesh_file << "\n*NODE\n";
  int count = 0;
  const auto ends = EndBodies(m, &count);
  for (int b = 1; b < count; ++b) {
    out << RefNode(b, top) << ", 0, 0, 0\n" << RefNode(b, top) + 1 << ", 0, 0, 0\n";
  }
  // Released ends: spring anchors 10 mm along each compliant member axis, from the origin.
  for (std::size_t i = 0; i < m.members.size(); ++i) {
    if (ends[i][1] < m.body_count) continue;
    const MemberFrame f = FrameOf(m.members[i]);
    const Eigen::Vector3d axes[3] = {f.x, f.y, f.z};
    for (int k = 0; k < 3; ++k) {
      if (m.members[i].end_b_compliance[static_cast<std::size_t>(k)] > 0) {
        const Eigen::Vector3d p = 0.01 * axes[k];
        out << fmt::format("{}, {:.12g}, {:.12g}, {:.12g}\n", RefNode(ends[i][1], top) + 2 + k,
                           p.x(), p.y(), p.z());
      }
    }
  }
  for (int b = 0; b < count; ++b) {
    // The ground may hold no face when every member reaches it through a released joint.
    if (faces[static_cast<std::size_t>(b)].empty() && b == kGround) continue;
    if (faces[static_cast<std::size_t>(b)].empty()) {
      throw std::invalid_argument("fe model: no mesh node on the faces of body " +
                                  std::to_string(b));
    }
    WriteSet(out, "B" + std::to_string(b), faces[static_cast<std::size_t>(b)]);
  }
  WriteSet(out, "PLATFORM", {RefNode(1, top), RefNode(1, top) + 1});
  out << "*MATERIAL,NAME=FLEXURE\n*ELASTIC\n"
      << fmt::format("{:.9g}, {:.6g}\n", m.material.e_pa, m.material.poisson)
      << "*SOLID SECTION,ELSET=BODY,MATERIAL=FLEXURE\n";
  if (!faces[kGround].empty()) out << "*BOUNDARY\nB0, 1, 3\n";
  for (int b = 1; b < count; ++b) {
    out << fmt::format("*RIGID BODY,NSET=B{},REF NODE={},ROT NODE={}\n", b, RefNode(b, top),
                       RefNode(b, top) + 1);
  }
  WriteReleases(out, m, ends, top);
  static constexpr const char* kAxis[] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  for (int k = 0; k < 6; ++k) {
    out << "** unit " << kAxis[k] << " on the platform\n*STEP\n*STATIC\n*CLOAD,OP=NEW\n"
        << fmt::format("{}, {}, 1.0\n", RefNode(1, top) + (k < 3 ? 0 : 1), k % 3 + 1)
        << "*NODE PRINT,NSET=PLATFORM\nU\n*NODE FILE\nU\n*EL FILE\nE\n*END STEP\n";
  }
}

Mat6 ReadPlatformCompliance(std::istream& dat, int ref_node, const std::string& origin) {
  Mat6 c = Mat6::Constant(NAN);
  std::string line;
  int n = 0, step = -1;
  while (std::getline(dat, line)) {
    ++n;
    if (line.find("displacements (vx,vy,vz) for set PLATFORM") != std::string::npos) {
      ++step;
      continue;
    }
    std::stringstream ss(line);
    int id = 0;
    double v[3];
    if (step < 0 || step > 5 || !(ss >> id >> v[0] >> v[1] >> v[2])) continue;
    if (id != ref_node && id != ref_node + 1) continue;
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(v[i])) Fail(origin, n, "displacement is not finite");
      c((id == ref_node ? 0 : 3) + i, step) = v[i];
    }
  }
  if (!c.allFinite()) Fail(origin, n, "fewer than six steps of platform displacement");
  return c;
}

std::vector<std::map<int, std::vector<double>>> ReadFrdBlocks(std::istream& frd,
                                                              const std::string& name,
                                                              const std::string& origin) {
  std::vector<std::map<int, std::vector<double>>> blocks;
  std::string line;
  int n = 0;
  bool in = false;
  while (std::getline(frd, line)) {
    ++n;
    if (line.rfind(" -4", 0) == 0) {
      std::stringstream ss(line.substr(3));
      std::string key;
      ss >> key;
      in = key == name;
      if (in) blocks.emplace_back();
      continue;
    }
    if (line.rfind(" -3", 0) == 0) in = false;
    if (!in || line.rfind(" -1", 0) != 0) continue;
    if (line.size() < 13) Fail(origin, n, "short node record");
    std::vector<double> v;
    for (std::size_t at = 13; at < line.size(); at += 12) {
      const std::string field = line.substr(at, 12);
      char* end = nullptr;
      const double x = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || !std::isfinite(x)) {
        Fail(origin, n, "'" + field + "' is not a finite number");
      }
      v.push_back(x);
    }
    blocks.back()[std::atoi(line.substr(3, 10).c_str())] = v;
  }
  if (blocks.empty()) Fail(origin, n, "no " + name + " block");
  return blocks;
}

Eigen::MatrixXd GaugeStrainFromNodes(const DesignModel& m,
                                     const std::map<int, Eigen::Vector3d>& nodes,
                                     const std::vector<std::map<int, std::vector<double>>>& steps,
                                     int fit_nodes) {
  const auto g_count = static_cast<Eigen::Index>(m.gauges.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(g_count, 6);
  if (steps.size() < 6) throw std::runtime_error("fe results: fewer than six strain steps");
  std::set<int> clamped;  // end-face nodes: the clamp's stress singularity is no gauge reading
  for (const auto& face : EndFaceNodes(m, nodes)) clamped.insert(face.begin(), face.end());
  for (Eigen::Index g = 0; g < g_count; ++g) {
    const GaugeGrid& grid = m.gauges[static_cast<std::size_t>(g)];
    const Eigen::Vector3d d = grid.direction;
    const Eigen::Vector3d w = grid.normal.cross(d);
    std::vector<std::pair<double, int>> surface;  // in-plane distance, node
    for (const auto& [id, p] : nodes) {
      const Eigen::Vector3d r = p - grid.point_m;
      if (std::abs(r.dot(grid.normal)) > 1e-7 || clamped.contains(id)) continue;
      surface.emplace_back(std::hypot(r.dot(d), r.dot(w)), id);
    }
    const auto n = std::min<std::size_t>(static_cast<std::size_t>(fit_nodes), surface.size());
    if (n < 3)
      throw std::runtime_error("fe results: fewer than 3 surface nodes under " + grid.name);
    std::partial_sort(surface.begin(), surface.begin() + static_cast<std::ptrdiff_t>(n),
                      surface.end());
    Eigen::MatrixXd a(static_cast<Eigen::Index>(n), 3);
    Eigen::MatrixXd rhs(static_cast<Eigen::Index>(n), 6);
    for (std::size_t i = 0; i < n; ++i) {
      const int id = surface[i].second;
      const Eigen::Vector3d r = nodes.at(id) - grid.point_m;
      a.row(static_cast<Eigen::Index>(i)) << 1.0, r.dot(d), r.dot(w);
      for (int k = 0; k < 6; ++k) {
        const auto it = steps[static_cast<std::size_t>(k)].find(id);
        if (it == steps[static_cast<std::size_t>(k)].end() || it->second.size() < 6) {
          throw std::runtime_error("fe results: no strain at node " + std::to_string(id));
        }
        const std::vector<double>& e = it->second;
        rhs(static_cast<Eigen::Index>(i), k) =
            d.x() * d.x() * e[0] + d.y() * d.y() * e[1] + d.z() * d.z() * e[2] +
            2 * (d.x() * d.y() * e[3] + d.y() * d.z() * e[4] + d.z() * d.x() * e[5]);
      }
    }
    // A plane through the nearest nodes' strains, read at the grid centre: for a strain that
    // varies linearly over the grid (beam bending) this is the grid's average.
    out.row(g) = a.completeOrthogonalDecomposition().solve(rhs).row(0);
  }
  return out;
}

}  // namespace ftstack::sim::design
