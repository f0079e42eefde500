#include "sim/design/explore.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "measurement/wrench.hpp"

namespace ftstack::sim::design {
namespace {

std::string LineColumn(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::to_string(line) + ":" + std::to_string(col);
}

double Finite(const nlohmann::json& v, const std::string& where) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw std::runtime_error(where + ": expected a finite number");
  }
  return v.get<double>();
}

double LateralStiffness(const DesignFigures& f) {
  return std::min({f.stiffness(0, 0), f.stiffness(1, 1), f.stiffness(2, 2)});
}

}  // namespace

Requirement ParseRequirement(const std::string& text, const std::string& origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::runtime_error(origin + ":" + LineColumn(text, e.byte) + ": not JSON (" + e.what() +
                             ")");
  }
  const std::string at = origin + ":1:1";
  if (!j.is_object()) throw std::runtime_error(at + ": a requirement is a JSON object");
  Requirement r;
  r.name = j.value("name", origin);
  r.note = "load cases from " + origin;
  if (j.contains("safety_factor"))
    r.safety_factor = Finite(j["safety_factor"], at + " safety_factor");
  if (!(r.safety_factor >= 1.0)) throw std::runtime_error(at + ": safety_factor must be >= 1");
  std::vector<Vec6> cases;
  if (j.contains("cases")) {
    if (!j["cases"].is_array()) throw std::runtime_error(at + ": cases must be an array");
    for (std::size_t i = 0; i < j["cases"].size(); ++i) {
      const auto& c = j["cases"][i];
      const std::string where = at + " cases[" + std::to_string(i) + "]";
      if (!c.is_array() || c.size() != 6) throw std::runtime_error(where + ": need 6 numbers");
      Vec6 w;
      for (int k = 0; k < 6; ++k) w(k) = Finite(c[static_cast<std::size_t>(k)], where);
      r.peak = r.peak.cwiseMax(w.cwiseAbs());
      cases.push_back(w);
    }
  }
  if (j.contains("envelope")) {
    const auto& e = j["envelope"];
    const std::string where = at + " envelope";
    if (!e.is_object()) throw std::runtime_error(where + ": must be an object");
    std::array<double, 4> v{};
    const char* keys[4] = {"fxy_n", "fz_n", "mxy_nm", "mz_nm"};
    for (int k = 0; k < 4; ++k) {
      v[static_cast<std::size_t>(k)] =
          e.contains(keys[k]) ? Finite(e[keys[k]], where + "." + keys[k]) : 0.0;
      if (v[static_cast<std::size_t>(k)] < 0)
        throw std::runtime_error(where + ": ranges must be >= 0");
    }
    if (!cases.empty()) throw std::runtime_error(at + ": give cases or an envelope, not both");
    r.loads = std::make_shared<EnvelopeLoads>(v[0], v[1], v[2], v[3]);
    r.peak << v[0], v[0], v[1], v[2], v[2], v[3];
    return r;
  }
  if (cases.empty()) throw std::runtime_error(at + ": no load cases and no envelope");
  r.loads = std::make_shared<CaseLoads>(cases);
  return r;
}

Requirement LoadRequirement(const std::string& name) {
  Requirement r;
  if (name == "panda-base") {
    r.name = name;
    r.note =
        "Franka Emika Panda base: 300 N horizontal, 410 N vertical, 280 N·m tilting, 190 N·m "
        "about the axis, all at once in any direction (figures as issue 13 states them)";
    r.loads = std::make_shared<EnvelopeLoads>(300, 410, 280, 190);
    r.peak << 300, 300, 410, 280, 280, 190;
    return r;
  }
  if (name == "yumi-estop") {
    r.name = name;
    r.note =
        "ABB YuMi at an emergency stop: 202 N·m tilting (x, taken in any direction), 122 N·m "
        "about z (normal operation 101/61); forces are not given — add them with a JSON file";
    r.loads = std::make_shared<EnvelopeLoads>(0, 0, 202, 122);
    r.peak << 0, 0, 0, 202, 202, 122;
    return r;
  }
  std::ifstream in(name);
  if (!in) throw std::runtime_error(name + ": cannot open (not panda-base, yumi-estop or a file)");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseRequirement(ss.str(), name);
}

std::string RequirementCheck::binding() const {
  if (yield >= gauge && yield >= buckling) return "yield stress";
  if (gauge >= buckling) return "gauge strain range";
  return "buckling";
}

RequirementCheck Check(const DesignModel& m, const Requirement& r) {
  RequirementCheck c;
  c.yield = WorstStress(m, *r.loads) * r.safety_factor / m.material.yield_pa;
  c.gauge = WorstGaugeStrain(m, *r.loads) / m.material.allowable_gauge_strain;
  c.buckling = WorstBucklingRatio(m, *r.loads) * r.safety_factor;
  return c;
}

void MarkPareto(std::vector<Candidate>* cs) {
  auto obj = [](const Candidate& c) {
    const DesignFigures& f = c.figures;
    return std::array<double, 4>{f.tilt_capacity_nm, f.force_range_n, -f.force_resolution_n,
                                 LateralStiffness(f)};
  };
  for (Candidate& a : *cs) {
    const auto oa = obj(a);
    a.pareto = a.model.beam_validity.empty();  // outside beam theory: not ranked
    if (!a.pareto) continue;
    for (const Candidate& b : *cs) {
      if (!b.model.beam_validity.empty()) continue;
      const auto ob = obj(b);
      bool all_ge = true, one_gt = false;
      for (int k = 0; k < 4; ++k) {
        all_ge = all_ge && ob[static_cast<std::size_t>(k)] >= oa[static_cast<std::size_t>(k)];
        one_gt = one_gt || ob[static_cast<std::size_t>(k)] > oa[static_cast<std::size_t>(k)];
      }
      if (all_ge && one_gt) {
        a.pareto = false;
        break;
      }
    }
  }
}

namespace {

std::vector<double> Grid(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(n == 1 ? lo : lo * std::pow(hi / lo, i / (n - 1.0)));
  return v;
}

void Add(std::vector<Candidate>* out, std::string id, DesignModel m, const SweepOptions& o,
         const Requirement* req) {
  Candidate c;
  c.id = std::move(id);
  c.figures = Evaluate(m, o.design);
  if (req != nullptr) c.check = Check(m, *req);
  c.model = std::move(m);
  out->push_back(std::move(c));
}

}  // namespace

namespace {

/// Longest leaf that keeps three nested stages (inner radius, two gaps) inside the envelope.
double MaxLeafLength(const SweepOptions& o, double cap) {
  const GuidedParams d;
  if (!(o.max_radius_m > 0)) return cap;
  return std::min(cap, (o.max_radius_m - d.inner_radius_m - 2 * d.gap_m) / 3.0);
}

}  // namespace

std::vector<Candidate> Sweep(const SweepOptions& o, const Requirement* req,
                             std::ostream* progress) {
  std::vector<Candidate> out;
  const int n = std::max(1, o.hub_spoke_steps);
  for (double hub : Grid(0.008, 0.06, n)) {
    for (double len : Grid(0.008, 0.05, n)) {
      for (double w : Grid(0.0015, 0.015, n)) {
        for (double h : Grid(0.0015, 0.015, n)) {
          HubSpokeParams p;
          p.hub_radius_m = hub;
          p.rim_radius_m = hub + len;
          p.beam_width_m = w;
          p.beam_height_m = h;
          if (o.max_radius_m > 0 && p.rim_radius_m > o.max_radius_m) continue;
          Add(&out, fmt::format("H{:03d}", out.size()), HubSpoke(p, o.readout), o, req);
        }
      }
    }
    if (progress != nullptr) *progress << "  hub-spoke: " << out.size() << " designs\n";
  }
  const std::size_t first_guided = out.size();
  const int g = std::max(1, o.guided_steps);
  const double l_hi = MaxLeafLength(o, 0.045);
  for (double len : Grid(std::min(0.02, 0.5 * l_hi), l_hi, g)) {
    if (l_hi < 0.004) break;  // no nested body fits the envelope
    for (double b : Grid(0.02, 0.05, g)) {
      for (double t : Grid(0.0008, 0.0025, g + 1)) {
        for (double tz : {t, 1.4 * t}) {
          for (double d : Grid(0.03, 0.08, g)) {
            GuidedParams p;
            p.leaf_length_m = len;
            p.leaf_width_m = b;
            p.leaf_thickness_m = t;
            p.leaf_thickness_z_m = tz;
            p.separation_m = d;
            Add(&out, fmt::format("G{:03d}", out.size() - first_guided), Guided(p, o.readout), o,
                req);
          }
        }
      }
    }
    if (progress != nullptr) *progress << "  guided: " << out.size() - first_guided << " designs\n";
  }
  MarkPareto(&out);
  return out;
}

namespace {

GuidedParams GuidedFrom(const DesignModel& m) {
  GuidedParams p;
  const auto& q = m.parameters;
  p.leaf_length_m = q.at("leaf_length_m");
  p.leaf_width_m = q.at("leaf_width_m");
  p.leaf_thickness_m = q.at("leaf_thickness_m");
  p.leaf_thickness_z_m = q.at("leaf_thickness_z_m");
  p.separation_m = q.at("separation_m");
  p.inner_radius_m = q.at("inner_radius_m");
  p.material = m.material;
  return p;
}

/// Lower is better. Phase 0: the force the requirement "uses" at the gauges (range × gauge
/// utilisation: lowered by geometry that keeps moments off the force gauges). Phase 1: met designs
/// inside the goal range by resolution, then by force range.
double RefineScore(const Candidate& c, int phase = 1) {
  if (!c.check.met() || !c.model.beam_validity.empty()) return INFINITY;
  if (phase == 0) return c.figures.force_range_n * c.check.gauge;
  if (c.figures.force_range_n > kGoalForceRangeN) return 1e3 + c.figures.force_range_n;
  return c.figures.force_resolution_n;
}

}  // namespace

int RefineGuided(std::vector<Candidate>* cs, const Requirement& req, const SweepOptions& o,
                 int starts) {
  std::vector<const Candidate*> seeds;
  for (const Candidate& c : *cs) {
    if (c.model.family == "guided" && c.check.met() && c.model.beam_validity.empty()) {
      seeds.push_back(&c);
    }
  }
  std::sort(seeds.begin(), seeds.end(), [](const Candidate* a, const Candidate* b) {
    return RefineScore(*a) < RefineScore(*b);
  });
  seeds.resize(std::min<std::size_t>(seeds.size(), static_cast<std::size_t>(starts)));
  std::vector<Candidate> found;
  int evaluations = 0;
  for (const Candidate* seed : seeds) {
    Candidate best = *seed;
    GuidedParams p = GuidedFrom(seed->model);
    double* dims[5] = {&p.leaf_thickness_m, &p.leaf_thickness_z_m, &p.leaf_width_m, &p.separation_m,
                       &p.leaf_length_m};
    // Bounds of the search (m): about the sweep's ranges widened by half (a bench-size body).
    const double lo[5] = {0.0004, 0.0004, 0.01, 0.015, 0.01};
    const double hi[5] = {0.004, 0.004, 0.075, 0.12, MaxLeafLength(o, 0.07)};
    for (int phase = 0; phase < 2; ++phase) {
      for (double step = 0.16; step > 0.01; step *= 0.5) {
        bool improved = true;
        while (improved) {
          improved = false;
          for (int k = 0; k < 5; ++k) {
            for (double f : {1 - step, 1 + step}) {
              const double keep = *dims[k];
              if (keep * f < lo[k] || keep * f > hi[k]) continue;
              *dims[k] = keep * f;
              Candidate c;
              try {
                c.model = Guided(p, o.readout);
              } catch (const std::invalid_argument&) {
                *dims[k] = keep;  // a degenerate geometry is no candidate
                continue;
              }
              c.figures = Evaluate(c.model, o.design);
              c.check = Check(c.model, req);
              ++evaluations;
              if (RefineScore(c, phase) < RefineScore(best, phase)) {
                best = std::move(c);
                improved = true;
              } else {
                *dims[k] = keep;
              }
            }
          }
        }
      }
    }
    best.id = fmt::format("R{:02d}", found.size());
    found.push_back(std::move(best));
  }
  for (Candidate& c : found) cs->push_back(std::move(c));
  MarkPareto(cs);
  return evaluations;
}

void PrintAssumptions(std::ostream& out, const DesignOptions& o, const Readout& r) {
  out << "Assumptions:\n"
      << "  linear elastic Timoshenko frames (shear factor 5/6; members wider than long bend\n"
      << "  with E/(1-nu^2)); no fillets or stress concentrations, ideal clamps, rigid\n"
      << "  hub/rim/stages; members with L < 2 h (a leaf's width: L < b/2) are outside beam\n"
      << "  theory and not ranked; stress = von Mises from the worst\n"
      << "  normal stress at section corners and the worst torsional shear (conservative);\n"
      << fmt::format(
             "  rated capacity per axis = min(gauge strain {:.0f} µε, yield / SF {:.2f}, "
             "fatigue endurance, Euler buckling (clamped-clamped) / SF);\n",
             1e6 * Steel174Ph().allowable_gauge_strain, o.safety_factor)
      << "  combined-load rule: |Fz|/Fz_r + |Mxy|/Mxy_r <= 1 and |Fxy|/Fxy_r + |Mz|/Mz_r <= 1;\n"
      << fmt::format(
             "  read-out: {} gain {} at {} SPS, excitation {:.1f} V, GF {:.2f}, full "
             "bridges (small signal);\n",
             ToString(r.adc.chip), r.adc.gain, r.adc.rate_hz, r.adc.excitation_v, r.gauge_factor)
      << "  resolution = 1σ noise through the least-squares calibration, white noise, native\n"
      << "  bandwidth = data rate / 2, lower bandwidths by averaging (√ scaling);\n"
      << fmt::format(
             "  natural frequencies: rigid tool {:.2f} kg, centre of mass z = {:.3f} m, "
             "radius of gyration {:.3f} m; the body's own mass neglected.\n",
             o.tool_mass_kg, o.tool_com_z_m, o.tool_gyration_m)
      << "Units: N, N·m, N/m, N·m/rad, Hz, Pa; wrench Fx Fy Fz Mx My Mz in the sensor frame.\n";
}

void PrintDesign(std::ostream& out, const Candidate& c, const DesignOptions& o) {
  const DesignFigures& f = c.figures;
  out << fmt::format("design {} (family {}, {})\n", c.id, c.model.family, c.model.material.name);
  out << " ";
  for (const auto& [k, v] : c.model.parameters) out << fmt::format(" {}={:.4g}", k, v);
  if (c.model.family == "hub-spoke" && c.model.parameters.contains("rim_radius_m")) {
    out << fmt::format(" envelope_radius_m={:.4g}", c.model.parameters.at("rim_radius_m"));
  }
  out << fmt::format("\n  capacity alone (SF {:.2f}):", o.safety_factor);
  for (int k = 0; k < 6; ++k) {
    out << fmt::format(" {} {:.4g} {} [{}]", kWrenchAxisNames[k], f.capacity(k),
                       kWrenchAxisUnits[k], ToString(f.binding[static_cast<std::size_t>(k)]));
  }
  out << fmt::format("\n  combined-load rule: capacities x {:.3f}\n", f.combined_scale);
  out << fmt::format("  resolution (1σ, {:.0f} Hz):", f.bandwidth_hz);
  for (int k = 0; k < 6; ++k)
    out << fmt::format(" {} {:.3g} {}", kWrenchAxisNames[k], f.resolution(k), kWrenchAxisUnits[k]);
  out << "\n  stiffness diagonal:";
  for (int k = 0; k < 6; ++k) {
    out << fmt::format(" {:.3g} {}", f.stiffness(k, k), k < 3 ? "N/m" : "N·m/rad");
  }
  out << "\n  natural frequencies with the tool (Hz):";
  for (int k = 0; k < 6; ++k) out << fmt::format(" {:.4g}", f.natural_hz(k));
  out << fmt::format(
      "\n  overload margin to yield at rated load: {:.2f}x; condition number {:.3g}\n",
      f.overload_margin, f.condition_number);
}

int PrintRequirementVerdict(std::ostream& out, const std::vector<Candidate>& cs,
                            const Requirement& req, int max_listed) {
  out << fmt::format("Requirement {} (safety factor {:.2f}): {}\n", req.name, req.safety_factor,
                     req.note);
  std::vector<const Candidate*> ok;
  int unranked = 0;
  for (const Candidate& c : cs) {
    if (c.check.met() && c.model.beam_validity.empty()) ok.push_back(&c);
    if (c.check.met() && !c.model.beam_validity.empty()) ++unranked;
  }
  std::sort(ok.begin(), ok.end(), [](const Candidate* a, const Candidate* b) {
    return a->figures.force_resolution_n < b->figures.force_resolution_n;
  });
  out << fmt::format("{} of {} designs meet it", ok.size(), cs.size());
  if (unranked > 0) {
    out << fmt::format(
        " ({} more meet it on beam figures but have members outside the slender-beam range: "
        "not ranked)",
        unranked);
  }
  out << ".\n";
  for (int i = 0; i < std::min<int>(max_listed, static_cast<int>(ok.size())); ++i) {
    const Candidate& c = *ok[static_cast<std::size_t>(i)];
    out << fmt::format(
        "  {} {}: force range {:.0f} N, force resolution {:.4f} N, tilt capacity {:.0f} N·m, "
        "utilisation yield {:.2f} gauge {:.2f} buckling {:.2f}\n",
        c.id, c.model.family, c.figures.force_range_n, c.figures.force_resolution_n,
        c.figures.tilt_capacity_nm, c.check.yield, c.check.gauge, c.check.buckling);
  }
  for (const std::string fam : {"hub-spoke", "guided"}) {
    const Candidate* closest = nullptr;  // smallest worst utilisation
    const Candidate* finest = nullptr;   // meets it with the finest force resolution
    double lever = 0;
    int met = 0;
    for (const Candidate& c : cs) {
      if (c.model.family != fam) continue;
      lever = std::max(lever, c.figures.tilt_capacity_nm / c.figures.capacity.head<2>().minCoeff());
      if (closest == nullptr || c.check.worst() < closest->check.worst()) closest = &c;
      if (!c.check.met() || !c.model.beam_validity.empty()) continue;
      ++met;
      if (finest == nullptr || c.figures.force_resolution_n < finest->figures.force_resolution_n) {
        finest = &c;
      }
    }
    if (closest == nullptr) continue;
    out << fmt::format("  {}: {} designs meet it; ", fam, met);
    if (finest != nullptr) {
      out << fmt::format("finest force resolution among them {:.4f} N ({}, force range {:.0f} N)",
                         finest->figures.force_resolution_n, finest->id,
                         finest->figures.force_range_n);
    } else {
      out << fmt::format(
          "closest {} works at {:.2f} of its limit, bound by {} (yield {:.2f}, "
          "gauge {:.2f}, buckling {:.2f})",
          closest->id, closest->check.worst(), closest->check.binding(), closest->check.yield,
          closest->check.gauge, closest->check.buckling);
    }
    out << fmt::format(";\n    largest lever Txy/Fxy (tilt over lateral force capacity) {:.3f} m",
                       lever);
    if (req.peak(0) > 0 && req.peak(3) > 0) {
      out << fmt::format(
          ": with a force range of {:.0f} N this family carries at most {:.0f} N·m tilting "
          "(requirement {:.0f} N·m, lever needed {:.3f} m)",
          kGoalForceRangeN, kGoalForceRangeN * lever, req.peak(3), req.peak(3) / kGoalForceRangeN);
    }
    out << "\n";
  }
  return static_cast<int>(ok.size());
}

bool MeetsGoal(const Candidate& c, const Requirement& req) {
  return req.safety_factor >= 1.5 && c.check.met() && c.model.beam_validity.empty() &&
         c.figures.force_range_n <= kGoalForceRangeN &&
         c.figures.force_resolution_n <= kGoalForceResolutionN;
}

void PrintGoal(std::ostream& out, const std::vector<Candidate>& cs, const Requirement& req) {
  const Candidate* best = nullptr;
  int n = 0;
  for (const Candidate& c : cs) {
    if (!MeetsGoal(c, req)) continue;
    ++n;
    if (best == nullptr || c.figures.force_resolution_n < best->figures.force_resolution_n)
      best = &c;
  }
  out << fmt::format(
      "Goal (carry {} at SF >= 1.5 with force range <= {:.0f} N and force resolution <= {:.2f} N): "
      "{} designs reach it.\n",
      req.name, kGoalForceRangeN, kGoalForceResolutionN, n);
  if (best != nullptr) {
    out << fmt::format(
        "  best: {} ({}) force range {:.0f} N, force resolution {:.4f} N, tilt capacity {:.0f} "
        "N·m, lever Txy/Fxy {:.2f} m, first natural frequency {:.0f} Hz\n",
        best->id, best->model.family, best->figures.force_range_n, best->figures.force_resolution_n,
        best->figures.tilt_capacity_nm,
        best->figures.tilt_capacity_nm / best->figures.capacity.head<2>().minCoeff(),
        best->figures.natural_hz(0));
    return;
  }
  for (const Candidate& c : cs) {
    if (c.check.met() && c.model.beam_validity.empty() &&
        (best == nullptr || c.figures.force_range_n < best->figures.force_range_n)) {
      best = &c;
    }
  }
  if (best != nullptr) {
    out << fmt::format(
        "  nearest: {} meets the loads with force range {:.0f} N, resolution {:.4f} N\n", best->id,
        best->figures.force_range_n, best->figures.force_resolution_n);
  }
}

}  // namespace ftstack::sim::design
