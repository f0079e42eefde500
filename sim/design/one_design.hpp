// One design at a time: a design named on the command line, its full figures as text and JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "sim/design/explore.hpp"

namespace ftstack::sim::design {

/// A design from "FAMILY:key=value,...": family hub-spoke (beams, hub_radius_m, rim_radius_m,
/// beam_width_m, beam_height_m, gauge_frac) or guided (leaf_length_m, leaf_width_m,
/// leaf_thickness_m, leaf_thickness_z_m, separation_m, inner_radius_m, gap_m, gauge_frac); the
/// keys not given keep the family's defaults. Throws std::invalid_argument naming the bad part.
[[nodiscard]] DesignModel ModelFromSpec(const std::string& spec, const Readout& r);

/// The spec that rebuilds a generated design ("hub-spoke:beams=4,..."), from its parameters.
[[nodiscard]] std::string SpecOf(const DesignModel& m);

/// Everything about one design: parameters, the slender-beam verdict, the 6×6 stiffness, the
/// strain of every gauge per unit wrench, the bridge outputs, capacities with the binding limit,
/// resolution and modes.
void PrintDesignDetail(std::ostream& out, const Candidate& c, const DesignOptions& o);
/// The same figures as JSON (units in the key names).
[[nodiscard]] nlohmann::json DesignJson(const Candidate& c, const DesignOptions& o);

}  // namespace ftstack::sim::design
