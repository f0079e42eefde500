// `ftsim pivot` — the crossed-strip flexure pivot solver (logic in sim/pivot/pivot_report).
#include <iostream>
#include <memory>

#include "sim/pivot/pivot_report.hpp"
#include "tools/ftsim/commands.hpp"

namespace ftstack::tools {

void AddPivotCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<sim::pivot::PivotCommandArgs>();
  auto* cmd = app.add_subcommand(
      "pivot",
      "crossed-strip flexure pivot: couple, centre shift and strip forces at a rotation and load");
  cmd->add_option("--E", args->e_pa, "Young's modulus (Pa)")->required();
  cmd->add_option("--L", args->length_m, "strip free length (m)")->required();
  cmd->add_option("--b", args->width_m, "strip width (m)")->required();
  cmd->add_option("--t", args->thickness_m, "strip thickness (m)")->required();
  cmd->add_option("--alpha-deg", args->alpha_deg, "strip angle from the pivot axis (deg)")
      ->required();
  cmd->add_option("--theta-deg", args->theta_deg, "rotation, counter-clockwise positive (deg)")
      ->required();
  cmd->add_option("--V", args->v_n, "axial load, > 0 pulls the body from the base (N)")->required();
  cmd->add_option("--H", args->h_n, "lateral load along +x (N)")->required();
  cmd->add_option("--yield-pa", args->yield_pa, "yield strength (Pa), default 1e9 (spring steel)");
  cmd->add_option("--lambda", args->lambda,
                  "crossing point as a fraction of the strip length from the base, default 0.5");
  cmd->add_option("--method", args->method, "exact (default, elastica) or wittrick");
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->add_option("--shape-csv", args->shape_csv,
                  "measured edge points x,y (pixels, any frame) of one strip: register them onto "
                  "the model's deformed strip and report the shape residual");
  cmd->add_option("--strip", args->strip, "strip the --shape-csv points belong to (1 or 2)");
  cmd->callback(
      [args, exit_code] { *exit_code = sim::pivot::RunPivotCommand(*args, std::cout, std::cerr); });
}

}  // namespace ftstack::tools
