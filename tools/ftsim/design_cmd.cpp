// `ftsim design` — capacities, resolution and modes of sensor bodies; sweeps against a requirement.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>

#include "sim/design/explore.hpp"
#include "sim/design/one_design.hpp"
#include "sim/design/report.hpp"
#include "sim/sensor_description.hpp"
#include "tools/ftsim/commands.hpp"
#include "tools/ftsim/design_one.hpp"

namespace ftstack::tools {
namespace {

struct DesignArgs {
  std::string sensor;
  std::string require;
  std::string report;
  std::string catalog;
  double safety_factor = 1.5;
  double bandwidth_hz = 0;
  double tool_mass_kg = 1.0;
  double tool_com_z_m = 0.05;
  double tool_gyration_m = 0.05;
  double yield_mpa = 0;
  double fatigue_mpa = 0;
  bool elastic_roots = false;
  int list = 8;
  int refine_starts = 6;
  double max_radius_m = 0;
  std::string eval;
  OneDesignOutput one;
};

int RunSensor(const DesignArgs& a, const sim::design::DesignOptions& o,
              const sim::design::Requirement* req) {
  const sim::SensorDescription d = sim::LoadSensorDescription(a.sensor);
  const auto* phys = dynamic_cast<const sim::PhysicalSensorModel*>(d.model.get());
  if (phys == nullptr) {
    std::cerr << "ftsim design: " << a.sensor
              << " is not a flexure (physical) sensor description\n";
    return kExitBadInput;
  }
  sim::design::Material mat =
      phys->spec().body.e_pa < 100e9 ? sim::design::Aluminium7075() : sim::design::Steel174Ph();
  mat.e_pa = phys->spec().body.e_pa;
  mat.poisson = phys->spec().body.poisson;
  if (phys->spec().allowable_strain > 0) mat.allowable_gauge_strain = phys->spec().allowable_strain;
  if (a.yield_mpa > 0) mat.yield_pa = a.yield_mpa * 1e6;
  if (a.fatigue_mpa > 0) mat.fatigue_pa = a.fatigue_mpa * 1e6;
  sim::FlexureSensorSpec spec = phys->spec();
  spec.body.shear_deformable = true;  // the design explorer's beams are Timoshenko beams
  spec.body.elastic_roots = a.elastic_roots;
  const sim::PhysicalSensorModel body(spec);
  sim::design::Candidate c;
  c.id = d.name;
  c.model = sim::design::FromPhysicalSensor(body, mat, d.adc.noise_rms_mvv, d.rate_hz);
  c.figures = sim::design::Evaluate(c.model, o);
  std::cout << "Material assumed: " << mat.name << " limits (yield " << mat.yield_pa / 1e6
            << " MPa, endurance " << mat.fatigue_pa / 1e6
            << " MPa) with the description's E = " << mat.e_pa / 1e9 << " GPa; read-out "
            << sim::ToString(d.adc_spec.chip) << " at " << d.rate_hz << " SPS, noise "
            << d.adc.noise_rms_mvv << " mV/V RMS per bridge\n";
  ReportOneDesign(c, o, a.one, nullptr);
  if (req != nullptr) {
    c.check = sim::design::Check(c.model, *req);
    return sim::design::PrintRequirementVerdict(std::cout, {c}, *req, a.list) > 0 ? kExitOk
                                                                                  : kExitNotMet;
  }
  return kExitOk;
}

/// The sweep (and refinement under a requirement), the goal winner's or a named design's full
/// figures. Returns the number of designs meeting the requirement (1 without), -1 on bad input.
int RunSweep(const DesignArgs& a, const sim::design::SweepOptions& so,
             const sim::design::Requirement* req, std::vector<sim::design::Candidate>* out,
             sim::design::FeCheck* fe, std::string* fe_id) {
  std::cout << "Sweeping the families:\n";
  std::vector<sim::design::Candidate>& cs = *out;
  cs = sim::design::Sweep(so, req, &std::cout);
  int met = 1;
  if (req) {
    const int n = sim::design::RefineGuided(&cs, *req, so, a.refine_starts);
    std::cout << "Refined the " << a.refine_starts << " best guided designs (" << n
              << " evaluations)\n";
    met = sim::design::PrintRequirementVerdict(std::cout, cs, *req, a.list);
    sim::design::PrintGoal(std::cout, cs, *req);
    const sim::design::Candidate* best = nullptr;
    for (const auto& c : cs) {
      if (sim::design::MeetsGoal(c, *req) &&
          (best == nullptr || c.figures.force_resolution_n < best->figures.force_resolution_n)) {
        best = &c;
      }
    }
    if (best != nullptr && a.eval.empty()) {
      std::cout << "Goal winner:\n";
      ReportOneDesign(*best, so.design, a.one, fe);
      *fe_id = best->id;
    }
  }
  if (!a.eval.empty()) {  // a design named in the listing
    const auto it =
        std::find_if(cs.begin(), cs.end(), [&](const auto& c) { return c.id == a.eval; });
    if (it == cs.end()) {
      std::cerr << "ftsim design: no design " << a.eval << " in this sweep (ids as listed: H…, G…, "
                << "R… with --require; or FAMILY:key=value,…)\n";
      return -1;
    }
    ReportOneDesign(*it, so.design, a.one, fe);
    *fe_id = it->id;
  }
  std::cout << "Pareto front (tilt capacity, force capacity, force resolution, stiffness):\n";
  int shown = 0;
  for (const auto& c : cs) {
    if (c.pareto && shown++ < a.list) sim::design::PrintDesign(std::cout, c, so.design);
  }
  return met;
}

int Run(const DesignArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  sim::design::SweepOptions so;
  so.design.safety_factor = a.safety_factor;
  so.design.bandwidth_hz = a.bandwidth_hz;
  so.design.tool_mass_kg = a.tool_mass_kg;
  so.design.tool_com_z_m = a.tool_com_z_m;
  so.design.tool_gyration_m = a.tool_gyration_m;
  so.max_radius_m = a.max_radius_m;
  std::unique_ptr<sim::design::Requirement> req;
  if (!a.require.empty()) {
    req = std::make_unique<sim::design::Requirement>(sim::design::LoadRequirement(a.require));
    so.design.safety_factor = std::max(so.design.safety_factor, req->safety_factor);
  }
  sim::design::PrintAssumptions(std::cout, so.design, so.readout);
  if (!a.sensor.empty()) return RunSensor(a, so.design, req.get());
  std::vector<sim::design::Candidate> cs;
  int met = 1;
  sim::design::FeCheck fe;
  std::string fe_id;
  if (a.eval.find(':') != std::string::npos) {  // one design from its parameters
    sim::design::Candidate c;
    c.id = "eval";
    c.model = sim::design::ModelFromSpec(a.eval, so.readout);
    c.figures = sim::design::Evaluate(c.model, so.design);
    if (req) c.check = sim::design::Check(c.model, *req);
    cs.push_back(c);
    sim::design::MarkPareto(&cs);  // alone it is on the front unless outside beam theory
    ReportOneDesign(cs.front(), so.design, a.one, &fe);
    fe_id = c.id;
    if (req) met = sim::design::PrintRequirementVerdict(std::cout, cs, *req, a.list);
  } else {
    met = RunSweep(a, so, req.get(), &cs, &fe, &fe_id);
    if (met < 0) return kExitBadInput;
  }
  if (!a.report.empty()) {
    const sim::design::Catalog cat = sim::design::LoadCatalog(a.catalog);
    std::ofstream out(a.report);
    sim::design::WriteDesignReport(out, cs, cat, req.get(), so.design,
                                   fe.meshes.empty() && fe.note.empty() ? nullptr : &fe, fe_id);
    if (!out) {
      std::cerr << "ftsim design: cannot write " << a.report << "\n";
      return kExitBadInput;
    }
    std::cout << "Report written to " << a.report << "\n";
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "Evaluated " << cs.size() << " designs in " << s << " s\n";
  return met > 0 ? kExitOk : kExitNotMet;
}

}  // namespace

void AddDesignCommand(CLI::App& app, int* exit_code) {
  auto a = std::make_shared<DesignArgs>();
  auto* cmd = app.add_subcommand(
      "design", "sensor-body design explorer: capacities, resolution, stiffness, modes, sweeps");
  cmd->add_option("--sensor", a->sensor, "evaluate one sensor description (ftstack-sensor/1 JSON)");
  cmd->add_option("--require", a->require, "panda-base, yumi-estop or a JSON file of load cases");
  cmd->add_option("--report", a->report, "write a self-contained HTML report");
  cmd->add_option("--catalog", a->catalog, "catalogue CSV (default: the compiled-in survey)");
  cmd->add_option("--safety-factor", a->safety_factor, "on yield and buckling (default 1.5)");
  cmd->add_option("--bandwidth-hz", a->bandwidth_hz, "resolution bandwidth (default: native)");
  cmd->add_option("--tool-mass-kg", a->tool_mass_kg, "rigid tool mass (default 1)");
  cmd->add_option("--tool-com-z-m", a->tool_com_z_m, "tool centre of mass on the axis (0.05)");
  cmd->add_option("--tool-gyration-m", a->tool_gyration_m, "tool radius of gyration (0.05)");
  cmd->add_option("--yield-mpa", a->yield_mpa, "--sensor: yield stress of the body");
  cmd->add_option("--fatigue-mpa", a->fatigue_mpa, "--sensor: endurance limit of the body");
  cmd->add_flag("--elastic-roots", a->elastic_roots,
                "--sensor: beam roots compliant in an elastic hub and rim (O'Donnell)");
  cmd->add_option("--list", a->list, "designs listed (default 8)");
  cmd->add_option("--max-radius-m", a->max_radius_m,
                  "sweep: body envelope radius limit, m (default: none)");
  cmd->add_option("--refine", a->refine_starts, "guided designs refined after the sweep (6)");
  cmd->add_option("--eval", a->eval,
                  "one design: FAMILY:key=value,... (hub-spoke, guided) or an id of the sweep's "
                  "listing (H012, G040, R00)");
  cmd->add_option("--json", a->one.json_path, "--eval/--sensor/goal winner: write its figures");
  cmd->add_flag("--fe-check", a->one.fe_check,
                "solid FE check with gmsh + CalculiX (the --eval design, --sensor, or the goal "
                "winner of a --require sweep)");
  cmd->add_option("--step", a->one.step_path,
                  "--eval/--sensor/goal winner: write the body as drawn as STEP (mm)");
  cmd->add_option("--stl", a->one.stl_path, "with --step: also its surface mesh as STL (mm)");
  cmd->add_option("--fe-dir", a->one.fe.work_dir, "FE files go here (default fe-check)");
  cmd->add_option("--fe-size-m", a->one.fe.element_size_m,
                  "first FE mesh's element size, m (default: shortest member / 8)");
  cmd->callback([a, exit_code] { *exit_code = Run(*a); });
}

}  // namespace ftstack::tools
