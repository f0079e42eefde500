#include "tools/ftsim/design_one.hpp"

#include <fstream>
#include <iostream>

#include "sim/design/one_design.hpp"

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
  if (out.json_path.empty()) return;
  std::ofstream f(out.json_path);
  f << j.dump(2) << "\n";
  if (!f) throw std::runtime_error("cannot write " + out.json_path);
  std::cout << "Figures written to " << out.json_path << "\n";
}

}  // namespace ftstack::tools
