// `ftsim design` on one design: full figures, the optional FE check, the JSON file.
#pragma once

#include <string>

#include "sim/design/explore.hpp"
#include "sim/design/fe_check.hpp"

namespace ftstack::tools {

struct OneDesignOutput {
  std::string json_path;  ///< "" : no JSON
  std::string step_path;  ///< "" : no CAD file; else the body as drawn (and stl_path if given)
  std::string stl_path;
  bool fe_check = false;
  sim::design::FeCheckOptions fe;
};

/// Prints every figure of `c`, runs the FE check when asked (result in *fe, may be null),
/// writes the body as drawn (STEP, STL) and the JSON file when asked. Throws std::runtime_error
/// when a file cannot be written.
void ReportOneDesign(const sim::design::Candidate& c, const sim::design::DesignOptions& o,
                     const OneDesignOutput& out, sim::design::FeCheck* fe);

}  // namespace ftstack::tools
