// Family "guided": nested parallelogram stages (see families.hpp).
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "sim/design/families.hpp"

namespace ftstack::sim::design {
namespace {

constexpr double kPi = std::numbers::pi;

struct Stage {
  Eigen::Vector3d c, l;  ///< compliant axis, leaf axis
  int inner_body, outer_body;
  double thickness_m;
  const char* name;
};

std::array<Stage, 3> Stages(const GuidedParams& p) {
  return {Stage{Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), kPlatform, 2,
                p.leaf_thickness_z_m, "z"},
          Stage{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 2, 3, p.leaf_thickness_m, "x"},
          Stage{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 3, kGround, p.leaf_thickness_m,
                "y"}};
}

void CheckParams(const GuidedParams& p) {
  for (double v : {p.leaf_length_m, p.leaf_width_m, p.leaf_thickness_m, p.leaf_thickness_z_m,
                   p.separation_m, p.inner_radius_m, p.gap_m}) {
    if (!std::isfinite(v) || v <= 0) {
      throw std::invalid_argument("guided family: dimensions must be positive and finite");
    }
  }
  if (!(p.gauge_frac > 0 && p.gauge_frac < 0.5) || p.elements_per_leaf < 1) {
    throw std::invalid_argument("guided family: gauge_frac in (0, 0.5), elements_per_leaf >= 1");
  }
}

/// Leaf index: stage·4 + side·2 + leaf (side, leaf ∈ {0: +, 1: −}).
int LeafIndex(int stage, int side, int leaf) { return stage * 4 + side * 2 + leaf; }

/// Element and local position of the point s_m from the outer root of a leaf.
std::pair<int, double> LeafPoint(const GuidedParams& p, int leaf, double s_m) {
  const double le = p.leaf_length_m / p.elements_per_leaf;
  const int k = std::min(p.elements_per_leaf - 1, static_cast<int>(s_m / le));
  return {leaf * p.elements_per_leaf + k, s_m - k * le};
}

}  // namespace

FrameModel GuidedFrame(const GuidedParams& p) {
  CheckParams(p);
  FrameModel f;
  f.body_count = 4;
  f.e_pa = p.material.e_pa;
  f.poisson = p.material.poisson;
  const auto stages = Stages(p);
  const int n = p.elements_per_leaf;
  for (int st = 0; st < 3; ++st) {
    const Stage& s = stages[static_cast<std::size_t>(st)];
    const double c_in = p.inner_radius_m + st * (p.leaf_length_m + p.gap_m);
    for (int side = 0; side < 2; ++side) {
      for (int leaf = 0; leaf < 2; ++leaf) {
        const double sg = side == 0 ? 1.0 : -1.0;
        const double lk = leaf == 0 ? 1.0 : -1.0;
        const Eigen::Vector3d inner = sg * c_in * s.l + lk * 0.5 * p.separation_m * s.c;
        const Eigen::Vector3d outer = inner + sg * p.leaf_length_m * s.l;
        Anchor prev{s.outer_body, -1, outer};
        for (int e = 0; e < n; ++e) {
          Anchor next{s.inner_body, -1, inner};
          if (e + 1 < n) {
            f.nodes_m.push_back(outer + (inner - outer) * (e + 1.0) / n);
            next = Anchor{-1, static_cast<int>(f.nodes_m.size()) - 1, Eigen::Vector3d::Zero()};
          }
          FrameElement el;
          el.a = prev;
          el.b = next;
          el.width_m = p.leaf_width_m;
          el.height_m = s.thickness_m;
          el.z_hint = s.c;
          el.label = std::string(s.name) + "-stage leaf";
          el.buckling_length_m = 0.5 * p.leaf_length_m;  // clamped–clamped
          el.member_length_m = p.leaf_length_m;
          f.elements.push_back(el);
          prev = next;
        }
      }
    }
  }
  return f;
}

namespace {

// The strain sketch of every leaf (nine stations, four faces) and the leaves as solid members
// (the FE check's geometry).
void AddLeafSketchAndMembers(const GuidedParams& p, const FrameSolution& sol,
                             const std::array<Stage, 3>& stages, DesignModel* model) {
  DesignModel& m = *model;
  for (int leaf = 0; leaf < 12; ++leaf) {
    const double t = stages[static_cast<std::size_t>(leaf / 4)].thickness_m;
    SketchSegment seg{sol.EndPoint(leaf * p.elements_per_leaf, false),
                      sol.EndPoint(leaf * p.elements_per_leaf + p.elements_per_leaf - 1, true),
                      {}};
    for (int i = 0; i <= 8; ++i) {
      const auto [e, s] = LeafPoint(p, leaf, p.leaf_length_m * i / 8.0);
      seg.stations.push_back({sol.AxialStrain(e, s, 0, 0.5 * t), sol.AxialStrain(e, s, 0, -0.5 * t),
                              sol.AxialStrain(e, s, 0.5 * p.leaf_width_m, 0),
                              sol.AxialStrain(e, s, -0.5 * p.leaf_width_m, 0)});
    }
    m.sketch.push_back(seg);
  }
  m.body_count = sol.model().body_count;
  for (int leaf = 0; leaf < 12; ++leaf) {
    const FrameElement& first =
        sol.model().elements[static_cast<std::size_t>(leaf * p.elements_per_leaf)];
    const FrameElement& last = sol.model().elements[static_cast<std::size_t>(
        leaf * p.elements_per_leaf + p.elements_per_leaf - 1)];
    SolidMember mb;
    mb.a_m = sol.EndPoint(leaf * p.elements_per_leaf, false);
    mb.b_m = sol.EndPoint(leaf * p.elements_per_leaf + p.elements_per_leaf - 1, true);
    mb.body_a = first.a.body;
    mb.body_b = last.b.body;
    mb.z_axis = first.z_hint;
    mb.width_m = first.width_m;
    mb.height_m = first.height_m;
    m.members.push_back(mb);
  }
}

}  // namespace

DesignModel Guided(const GuidedParams& p, const Readout& r) {
  const FrameSolution sol(GuidedFrame(p));
  DesignModel m;
  m.family = "guided";
  m.name = "guided";
  m.material = p.material;
  m.parameters = {
      {"leaf_length_m", p.leaf_length_m},       {"leaf_width_m", p.leaf_width_m},
      {"leaf_thickness_m", p.leaf_thickness_m}, {"leaf_thickness_z_m", p.leaf_thickness_z_m},
      {"separation_m", p.separation_m},         {"inner_radius_m", p.inner_radius_m}};
  // Envelope of the nested layout (for tables; not a parameter): outermost leaf roots.
  m.parameters["envelope_radius_m"] = p.inner_radius_m + 3 * p.leaf_length_m + 2 * p.gap_m;
  m.stiffness = sol.Stiffness();
  const auto stages = Stages(p);
  std::vector<Row6> gauges;
  std::vector<Row6> bridges;
  const double k_bridge = 1000.0 * r.gauge_factor / 4.0;
  auto strain = [&](int leaf, double s_m, double z_sign) {
    const auto [e, s] = LeafPoint(p, leaf, s_m);
    const Stage& stage = stages[static_cast<std::size_t>(leaf / 4)];
    const double t = stage.thickness_m;
    const Row6 row = sol.AxialStrain(e, s, 0.0, z_sign * 0.5 * t);
    gauges.push_back(row);
    const Eigen::Vector3d outer = sol.EndPoint(leaf * p.elements_per_leaf, false);
    const Eigen::Vector3d inner =
        sol.EndPoint(leaf * p.elements_per_leaf + p.elements_per_leaf - 1, true);
    GaugeGrid g;
    g.direction = (inner - outer).normalized();
    g.normal = z_sign * stage.c;
    g.point_m = outer + g.direction * s_m + 0.5 * t * g.normal;
    g.name = std::string(stage.name) + (s_m < 0.25 * p.leaf_length_m ? " force" : " moment") +
             ((leaf % 4) / 2 == 0 ? ", + side" : ", - side") +
             (leaf % 2 == 0 ? " upper leaf" : " lower leaf") + (z_sign > 0 ? ", top" : ", bottom");
    m.gauges.push_back(g);
    return row;
  };
  const double root = p.gauge_frac * p.leaf_length_m;
  const double mid = 0.5 * p.leaf_length_m;
  // Gauge rows, in this order (one statement per gauge: the order is part of the contract):
  // per stage z, x, y the force bridge — + side upper leaf at the root, top then bottom face, then
  // the − side upper leaf likewise; then per stage the moment bridge — the + side parallelogram's
  // upper leaf at mid-leaf, top then bottom, then its lower leaf likewise.
  for (int st = 0; st < 3; ++st) {
    // Force bridge: bending adds (top − bottom face of each leaf), the two sides add.
    const int a = LeafIndex(st, 0, 0);
    const int b = LeafIndex(st, 1, 0);
    const Row6 at = strain(a, root, 1);
    const Row6 ab = strain(a, root, -1);
    const Row6 bt = strain(b, root, 1);
    const Row6 bb = strain(b, root, -1);
    bridges.push_back(k_bridge * (at - ab + bt - bb));
  }
  for (int st = 0; st < 3; ++st) {
    // Moment bridge: push–pull of the two leaves adds, their bending cancels.
    const int u = LeafIndex(st, 0, 0);
    const int d = LeafIndex(st, 0, 1);
    const Row6 ut = strain(u, mid, 1);
    const Row6 ub = strain(u, mid, -1);
    const Row6 dt = strain(d, mid, 1);
    const Row6 db = strain(d, mid, -1);
    bridges.push_back(k_bridge * (ut + ub - dt - db));
  }
  m.gauge_strain = Eigen::MatrixXd(static_cast<Eigen::Index>(gauges.size()), 6);
  for (std::size_t i = 0; i < gauges.size(); ++i)
    m.gauge_strain.row(static_cast<Eigen::Index>(i)) = gauges[i];
  m.sensitivity_mvv = Eigen::MatrixXd(6, 6);
  for (int i = 0; i < 6; ++i) m.sensitivity_mvv.row(i) = bridges[static_cast<std::size_t>(i)];

  const int ne = static_cast<int>(sol.model().elements.size());
  m.stress_normal = Eigen::MatrixXd(ne * 8, 6);
  m.stress_shear = Eigen::MatrixXd(ne, 6);
  for (int e = 0; e < ne; ++e) {
    const FrameElement& fe = sol.model().elements[static_cast<std::size_t>(e)];
    const BeamSection& sc = sol.Section(e);
    int row = 0;
    for (double s : {0.0, sol.Length(e)}) {
      for (double y : {-0.5, 0.5}) {
        for (double z : {-0.5, 0.5}) {
          m.stress_normal.row(e * 8 + row++) =
              sol.NormalStress(e, s, y * fe.width_m, z * fe.height_m);
        }
      }
    }
    m.stress_shear.row(e) =
        sol.SectionAt(e, 0).row(3) * RectangleTorsionShearPerNm(fe.width_m, fe.height_m);
    const double i_min = std::min(sc.iy_m4, sc.iz_m4);
    m.buckling.push_back({sol.SectionAt(e, 0).row(0),
                          kPi * kPi * sc.e_pa * i_min / std::pow(fe.buckling_length_m, 2)});
  }
  AddLeafSketchAndMembers(p, sol, stages, &m);
  for (const Stage& st : stages) {
    const std::string v = SlenderBeamViolation(p.leaf_length_m, p.leaf_width_m, st.thickness_m);
    if (!v.empty() && m.beam_validity.empty()) m.beam_validity = st.name + (" stage leaves: " + v);
  }
  m.bridge_noise_mvv = ReadoutNoiseMvv(r);
  m.native_bandwidth_hz = 0.5 * r.adc.rate_hz;
  return m;
}

}  // namespace ftstack::sim::design
