// The design explorer's self-contained HTML report: catalogue scatter, designs, Pareto, strain
// maps.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "sim/design/catalog.hpp"
#include "sim/design/explore.hpp"
#include "sim/design/fe_check.hpp"

namespace ftstack::sim::design {

/// Writes one HTML page (inline SVG, no scripts, no network). The fitted catalogue exponent is
/// also in an element with id "trend-exponent" (confirmed rows) for tests and readers.
/// With `fe` (may be null) the page ends with the FE check of design `fe_id`.
void WriteDesignReport(std::ostream& out, const std::vector<Candidate>& designs,
                       const Catalog& catalog, const Requirement* req, const DesignOptions& o,
                       const FeCheck* fe = nullptr, const std::string& fe_id = "");
/// The FE check as a page section: which figure comes from which model, the model/FE ratios as
/// a chart and a table, both meshes.
void WriteFeCheckSection(std::ostream& out, const std::string& id, const FeCheck& c);

}  // namespace ftstack::sim::design
