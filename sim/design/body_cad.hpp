// The designed body as drawn, one solid through gmsh's OpenCASCADE kernel: STEP and STL export.
#pragma once

#include <Eigen/Dense>
#include <ostream>
#include <string>
#include <vector>

#include "sim/design/design.hpp"

namespace ftstack::sim::design {

/// How the blocks the beam model keeps rigid are drawn (all dimensions from the design's own):
/// - hub-spoke: a hub disk of hub_radius_m, the beams (from the axis into the rim), a rim ring
///   from rim_radius_m out by max(beam width, height), all beam_height_m deep about z = 0; per
///   beam one hub hole (Ø 0.3·hub radius on the 0.6·hub radius circle) and one rim hole
///   (Ø 0.4·rim width on the rim's mid circle), both half-way between the beams, through z.
/// - guided: the leaves as in the model; the platform a block between the z stage's inner roots;
///   each intermediate stage and the ground a rectangular frame of plates `block_m` thick
///   (max(leaf width / 4, 3 × the thicker leaf)) joining its leaves' roots; two platform holes
///   (Ø min(inner radius, leaf width) / 4, x = ±inner radius / 2) and two holes through each
///   of the ground's end plates (Ø block / 2, between the leaf roots and the side plates), along z.
/// Every gauge grid is imprinted as a square pad (side pad_m) centred on its site.
struct BodyDrawing {
  double volume_m3 = 0;  ///< of the solid, as the kernel computes it
  int solids = 0;
  double pad_m = 0;
  double block_m = 0;            ///< guided: plate thickness of the stage blocks
  std::vector<int> gauge_faces;  ///< per gauge: the imprinted face's tag in the STEP model
};

/// Draws `m`, writes the STEP file (and the STL surface mesh when stl_path is not empty).
/// Throws std::invalid_argument when the layout does not fit (parts that would collide,
/// holes that would cut a beam) and std::runtime_error when the kernel fails or a file
/// cannot be written.
[[nodiscard]] BodyDrawing WriteBodyCad(const DesignModel& m, const std::string& step_path,
                                       const std::string& stl_path);

/// The drawing's summary and every gauge site (m) with its imprinted face.
void PrintBodyDrawing(std::ostream& out, const DesignModel& m, const BodyDrawing& d,
                      const std::string& step_path, const std::string& stl_path);

}  // namespace ftstack::sim::design
