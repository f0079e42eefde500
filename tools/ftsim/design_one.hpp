// `ftsim design` on one design: full figures, the optional FE check, the JSON file.
#pragma once

#include <string>

#include "sim/design/explore.hpp"
#include "sim/design/fe_check.hpp"

namespace ftstack::tools {

struct OneDesignOutput {
  std::string json_path;  ///< "" : no JSON
  bool fe_check = false;
  sim::design::FeCheckOptions fe;
};

/// Prints every figure of `c`, runs the FE check when asked (result in *fe, may be null) and
/// writes the JSON file when asked. Throws std::runtime_error when a file cannot be written.
void ReportOneDesign(const sim::design::Candidate& c, const sim::design::DesignOptions& o,
                     const OneDesignOutput& out, sim::design::FeCheck* fe);

}  // namespace ftstack::tools
