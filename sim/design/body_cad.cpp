#include "sim/design/body_cad.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace ftstack::sim::design {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMm = 1000.0;  // the drawing is in millimetres (STEP's unit for a shop)

using DimTags = std::vector<std::pair<int, int>>;

/// gmsh keeps global state: one session per drawing, closed on every path out.
struct GmshSession {
  GmshSession() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::model::add("body");
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

double Param(const DesignModel& m, const char* key) {
  const auto it = m.parameters.find(key);
  if (it == m.parameters.end()) {
    throw std::invalid_argument(fmt::format("CAD drawing: design has no parameter {}", key));
  }
  return it->second;
}

/// Axis-aligned box from its corners in metres.
int Box(const Eigen::Vector3d& lo_m, const Eigen::Vector3d& hi_m) {
  const Eigen::Vector3d d = hi_m - lo_m;
  return gmsh::model::occ::addBox(kMm * lo_m.x(), kMm * lo_m.y(), kMm * lo_m.z(), kMm * d.x(),
                                  kMm * d.y(), kMm * d.z());
}

/// Through-hole along z at (x, y), from z0 to z1 (m).
int HoleZ(double x_m, double y_m, double z0_m, double z1_m, double d_m) {
  return gmsh::model::occ::addCylinder(kMm * x_m, kMm * y_m, kMm * z0_m, 0, 0, kMm * (z1_m - z0_m),
                                       kMm * 0.5 * d_m);
}

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("CAD drawing: the layout does not fit: " + what);
}

struct Parts {
  DimTags solids, holes;
};

Parts HubSpokeParts(const DesignModel& m) {
  const double r_hub = Param(m, "hub_radius_m"), r_rim = Param(m, "rim_radius_m");
  const double w = Param(m, "beam_width_m"), h = Param(m, "beam_height_m");
  const int n = static_cast<int>(m.members.size());
  const double rim_w = std::max(w, h);
  Require(n >= 2, "fewer than two beams");
  Require(0.5 * w < r_hub * std::sin(kPi / n), "the beams overlap at the hub");
  const double beam_end = r_rim + 0.5 * rim_w;
  Require(std::hypot(beam_end, 0.5 * w) < r_rim + rim_w, "a beam pokes out of the rim");
  const double rim_hole_d = 0.4 * rim_w;
  Require(beam_end * std::sin(kPi / n) > 0.5 * (w + rim_hole_d), "a rim hole cuts a beam");
  Parts p;
  const auto occ = [](double z0, double dz, double r) {
    return gmsh::model::occ::addCylinder(0, 0, z0, 0, 0, dz, r);
  };
  p.solids.push_back({3, occ(-kMm * 0.5 * h, kMm * h, kMm * r_hub)});
  const int outer = occ(-kMm * 0.5 * h, kMm * h, kMm * (r_rim + rim_w));
  const int inner = occ(-kMm * 0.5 * h, kMm * h, kMm * r_rim);
  DimTags ring;
  std::vector<DimTags> map;
  gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, ring, map);
  p.solids.insert(p.solids.end(), ring.begin(), ring.end());
  for (const SolidMember& b : m.members) {
    const Eigen::Vector3d dir = (b.b_m - b.a_m).normalized();
    const int t = Box({0, -0.5 * w, -0.5 * h}, {beam_end, 0.5 * w, 0.5 * h});
    gmsh::model::occ::rotate({{3, t}}, 0, 0, 0, 0, 0, 1, std::atan2(dir.y(), dir.x()));
    p.solids.push_back({3, t});
    const double mid = std::atan2(dir.y(), dir.x()) + kPi / n;  // half-way to the next beam
    const Eigen::Vector3d u(std::cos(mid), std::sin(mid), 0);
    const Eigen::Vector3d a = 0.6 * r_hub * u, c = (r_rim + 0.5 * rim_w) * u;
    p.holes.push_back({3, HoleZ(a.x(), a.y(), -0.5 * h, 0.5 * h, 0.3 * r_hub)});
    p.holes.push_back({3, HoleZ(c.x(), c.y(), -0.5 * h, 0.5 * h, rim_hole_d)});
  }
  return p;
}

/// A rectangular frame about the axis `a` of plates e thick: two end plates across axis u at
/// ±[u_in, u_in + e] spanning ±v_half along v, and two side plates across v at ±[v_half − e,
/// v_half] between them; ±a_half along a.
void Frame(int u, int v, double u_in, double v_half, double a_half, double e, Parts* p) {
  const int a = 3 - u - v;
  for (double s : {1.0, -1.0}) {
    Eigen::Vector3d lo, hi;
    lo[a] = -a_half, hi[a] = a_half;
    lo[u] = s > 0 ? u_in : -u_in - e, hi[u] = s > 0 ? u_in + e : -u_in;
    lo[v] = -v_half, hi[v] = v_half;
    p->solids.push_back({3, Box(lo, hi)});
    lo[u] = -u_in, hi[u] = u_in;
    lo[v] = s > 0 ? v_half - e : -v_half, hi[v] = s > 0 ? v_half : -v_half + e;
    p->solids.push_back({3, Box(lo, hi)});
  }
}

Parts GuidedParts(const DesignModel& m, double* block_m) {
  const double len = Param(m, "leaf_length_m"), b = Param(m, "leaf_width_m");
  const double t = Param(m, "leaf_thickness_m"), tz = Param(m, "leaf_thickness_z_m");
  const double d = Param(m, "separation_m"), c0 = Param(m, "inner_radius_m");
  const double gap = 0.5 * (Param(m, "envelope_radius_m") - c0 - 3 * len);
  const double c1 = c0 + len + gap, c2 = c1 + len + gap;
  const double e = std::max(0.25 * b, 3 * std::max(t, tz));
  *block_m = e;
  const double z2 = std::max(0.5 * (d + tz), 0.5 * b), x3 = std::max(0.5 * (d + t), 0.5 * b);
  const double y0 = c1 + len + 2 * e + gap;
  Require(c1 - e > 0.5 * b, "the x stage's block meets the z stage's leaves");
  Require(c2 - e > z2, "the y stage's block meets the x stage's block");
  Require(0.5 * (d + t) <= c0 + len + e && 0.5 * (d + t) <= c1 + len + e,
          "leaf roots overhang their blocks");
  Parts p;
  for (const SolidMember& mb : m.members) {  // the leaves, axis-aligned boxes
    const Eigen::Vector3d x = (mb.b_m - mb.a_m).normalized();
    const Eigen::Vector3d y = mb.z_axis.cross(x);
    const Eigen::Vector3d half =
        0.5 * (mb.width_m * y.cwiseAbs() + mb.height_m * mb.z_axis.cwiseAbs());
    p.solids.push_back({3, Box(mb.a_m.cwiseMin(mb.b_m) - half, mb.a_m.cwiseMax(mb.b_m) + half)});
  }
  p.solids.push_back({3, Box({-c0, -0.5 * b, -z2}, {c0, 0.5 * b, z2})});  // platform
  Frame(0, 1, c0 + len, c1, z2, e, &p);                                   // z → x stage
  Frame(1, 2, c1 + len, c2, x3, e, &p);                                   // x → y stage
  Frame(2, 1, c2 + len, y0, x3, e, &p);                                   // ground
  const double ph = 0.25 * std::min(c0, b);
  for (double s : {1.0, -1.0}) p.holes.push_back({3, HoleZ(0.5 * s * c0, 0, -z2, z2, ph)});
  const double yh = 0.5 * (y0 - e + 0.5 * (d + t)), gh = 0.5 * e;
  Require(yh - 0.5 * gh > 0.5 * (d + t) && yh + 0.5 * gh < y0 - e, "no room for ground holes");
  for (double zs : {1.0, -1.0}) {
    const double z0 = zs > 0 ? c2 + len : -c2 - len - e;
    for (double ys : {1.0, -1.0}) p.holes.push_back({3, HoleZ(0, ys * yh, z0, z0 + e, gh)});
  }
  return p;
}

/// Side of the square pad imprinted at every gauge site: at most 2 mm, under half the side of
/// the face it sits on (of the member nearest the site), and 0.8 of the distance to the nearest
/// gauge on a parallel face.
double PadSide(const DesignModel& m) {
  double s = 0.002;
  for (const GaugeGrid& g : m.gauges) {
    const SolidMember* near = nullptr;
    double near_d = std::numeric_limits<double>::infinity();
    for (const SolidMember& mb : m.members) {
      const Eigen::Vector3d ab = mb.b_m - mb.a_m;
      const double f = std::clamp((g.point_m - mb.a_m).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      const double d = (g.point_m - mb.a_m - f * ab).norm();
      if (d < near_d) near_d = d, near = &mb;
    }
    if (near == nullptr) continue;
    const bool on_height_face = std::abs(g.normal.dot(near->z_axis)) > 0.5;
    s = std::min(s, 0.5 * (on_height_face ? near->width_m : near->height_m));
  }
  for (std::size_t i = 0; i < m.gauges.size(); ++i) {
    for (std::size_t j = i + 1; j < m.gauges.size(); ++j) {
      if (m.gauges[i].normal.dot(m.gauges[j].normal) < 0.999) continue;
      s = std::min(s, 0.8 * (m.gauges[i].point_m - m.gauges[j].point_m).norm());
    }
  }
  return s;
}

int Pad(const GaugeGrid& g, double side_m) {
  const Eigen::Vector3d u = g.direction.normalized(), v = g.normal.cross(u).normalized();
  std::vector<int> pts, lines;
  for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const Eigen::Vector3d q = kMm * (g.point_m + 0.5 * side_m * (a * u + b * v));
    pts.push_back(gmsh::model::occ::addPoint(q.x(), q.y(), q.z()));
  }
  for (std::size_t k = 0; k < 4; ++k)
    lines.push_back(gmsh::model::occ::addLine(pts[k], pts[(k + 1) % 4]));
  return gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop(lines)});
}

}  // namespace

BodyDrawing WriteBodyCad(const DesignModel& m, const std::string& step_path,
                         const std::string& stl_path) {
  BodyDrawing out;
  const GmshSession session;
  Parts parts;
  if (m.family == "hub-spoke") {
    parts = HubSpokeParts(m);
  } else if (m.family == "guided") {
    parts = GuidedParts(m, &out.block_m);
  } else {
    throw std::invalid_argument("CAD drawing: no drawing for family " + m.family);
  }
  DimTags body, cut, imprinted;
  std::vector<DimTags> map;
  const DimTags first(parts.solids.begin(), parts.solids.begin() + 1);
  const DimTags rest(parts.solids.begin() + 1, parts.solids.end());
  gmsh::model::occ::fuse(first, rest, body, map);
  gmsh::model::occ::cut(body, parts.holes, cut, map);
  out.pad_m = PadSide(m);
  DimTags pads;
  for (const GaugeGrid& g : m.gauges) pads.push_back({2, Pad(g, out.pad_m)});
  gmsh::model::occ::fragment(cut, pads, imprinted, map);
  gmsh::model::occ::synchronize();
  DimTags volumes, faces;
  gmsh::model::getEntities(volumes, 3);
  gmsh::model::getEntities(faces, 2);
  out.solids = static_cast<int>(volumes.size());
  for (const auto& [dim, tag] : volumes) {
    double v = 0;
    gmsh::model::occ::getMass(dim, tag, v);
    out.volume_m3 += v / (kMm * kMm * kMm);
  }
  std::vector<int> volume_tags;
  for (const auto& dt : volumes) volume_tags.push_back(dt.second);
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, volume_tags), "body");
  const double area = kMm * kMm * out.pad_m * out.pad_m;
  for (std::size_t g = 0; g < m.gauges.size(); ++g) {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (const auto& [dim, tag] : faces) {
      double a = 0, x = 0, y = 0, z = 0;
      gmsh::model::occ::getMass(dim, tag, a);
      if (std::abs(a - area) > 1e-3 * area) continue;
      gmsh::model::occ::getCenterOfMass(dim, tag, x, y, z);
      const double dist = (Eigen::Vector3d(x, y, z) - kMm * m.gauges[g].point_m).norm();
      if (dist < best_d) best_d = dist, best = tag;
    }
    if (best < 0 || best_d > 1e-6 * kMm) {
      throw std::runtime_error(fmt::format("CAD drawing: gauge {} ({}) did not imprint on the body",
                                           g, m.gauges[g].name));
    }
    out.gauge_faces.push_back(best);
    gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, {best}),
                                 fmt::format("gauge {}: {}", g, m.gauges[g].name));
  }
  auto write = [](const std::string& path) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    gmsh::write(path);
    if (!std::filesystem::exists(path)) throw std::runtime_error("cannot write " + path);
  };
  write(step_path);
  if (!stl_path.empty()) {
    // Facets only need to follow curved faces (24 per full circle); flat faces stay coarse.
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 24);
    gmsh::option::setNumber("Mesh.MeshSizeMax", kMm * std::cbrt(out.volume_m3));
    gmsh::option::setNumber("Mesh.SaveAll", 1);  // every face, not only the gauge pads' groups
    gmsh::model::mesh::generate(2);
    write(stl_path);
  }
  return out;
}

void PrintBodyDrawing(std::ostream& out, const DesignModel& m, const BodyDrawing& d,
                      const std::string& step_path, const std::string& stl_path) {
  out << fmt::format(
      "Body as drawn (gmsh/OpenCASCADE, millimetres): {} solid(s), volume {:.6g} mm^3; "
      "STEP {}{}\n",
      d.solids, d.volume_m3 * 1e9, step_path, stl_path.empty() ? "" : ", STL " + stl_path);
  if (d.block_m > 0)
    out << fmt::format("  stage blocks: plates {:.4g} mm thick\n", 1e3 * d.block_m);
  out << fmt::format("  gauge sites, imprinted as {:.3g} mm square pads (x y z in mm, face):\n",
                     1e3 * d.pad_m);
  for (std::size_t g = 0; g < m.gauges.size(); ++g) {
    const Eigen::Vector3d p = 1e3 * m.gauges[g].point_m;
    out << fmt::format("    {:3d}  {:9.4f} {:9.4f} {:9.4f}  face {:4d}  {}\n", g, p.x(), p.y(),
                       p.z(), d.gauge_faces[g], m.gauges[g].name);
  }
}

}  // namespace ftstack::sim::design
