#include "tools/ftsim/design_one.hpp"

#include <fstream>
#include <iostream>

#include "sim/design/one_design.hpp"
#ifdef FTSTACK_HAVE_CAD
#include "sim/design/body_cad.hpp"
#endif

namespace ftstack::tools {

void ReportOneDesign(const sim::design::Candidate& c, const sim::design::DesignOptions& o,
                     const OneDesignOutput& out, sim::design::FeCheck* fe) {
  sim::design::PrintDesignDetail(std::cout, c, o);
  nlohmann::json j = sim::design::DesignJson(c, o);
  if (out.fe_check) {
    const sim::design::FeCheck check = sim::design::RunFeCheck(c.model, out.fe, &std::cout);
    sim::design::PrintFeCheck(std::cout, check);
    j["fe_check"] = sim::design::FeCheckJson(check);
    if (fe != nullptr) *fe = check;
  }
  if (out.step_path.empty() && !out.stl_path.empty()) {
    throw std::invalid_argument("--stl " + out.stl_path +
                                " needs --step (the STEP file is the body)");
  }
  if (!out.step_path.empty()) {
#ifdef FTSTACK_HAVE_CAD
    const sim::design::BodyDrawing d =
        sim::design::WriteBodyCad(c.model, out.step_path, out.stl_path);
    sim::design::PrintBodyDrawing(std::cout, c.model, d, out.step_path, out.stl_path);
    j["cad"] = {{"step", out.step_path},       {"stl", out.stl_path},    {"volume_m3", d.volume_m3},
                {"solids", d.solids},          {"gauge_pad_m", d.pad_m}, {"block_m", d.block_m},
                {"gauge_faces", d.gauge_faces}};
#else
    throw std::runtime_error(
        "this ftsim was built without the gmsh C++ API: apt-get install libgmsh-dev and "
        "reconfigure to write " +
        out.step_path);
#endif
  }
  if (out.json_path.empty()) return;
  std::ofstream f(out.json_path);
  f << j.dump(2) << "\n";
  if (!f) throw std::runtime_error("cannot write " + out.json_path);
  std::cout << "Figures written to " << out.json_path << "\n";
}

}  // namespace ftstack::tools
