// The design explorer's self-contained HTML report: catalogue scatter, designs, Pareto, strain
// maps.
#pragma once

#include <ostream>
#include <vector>

#include "sim/design/catalog.hpp"
#include "sim/design/explore.hpp"

namespace ftstack::sim::design {

/// Writes one HTML page (inline SVG, no scripts, no network). The fitted catalogue exponent is
/// also in an element with id "trend-exponent" (confirmed rows) for tests and readers.
void WriteDesignReport(std::ostream& out, const std::vector<Candidate>& designs,
                       const Catalog& catalog, const Requirement* req, const DesignOptions& o);

}  // namespace ftstack::sim::design
