// Solid FE check of one design with gmsh and CalculiX (external programs, found at run time).
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "sim/design/design.hpp"
#include "sim/design/fe_deck.hpp"

namespace ftstack::sim::design {

struct FeCheckOptions {
  std::string work_dir = "fe-check";  ///< geometry, meshes, decks and results go here
  double element_size_m = 0;          ///< first mesh; 0: the shortest member / 8
  double refinement = 1.5;            ///< second mesh: element size / refinement
  int min_layers = 2;                 ///< hexahedra through each section side (first mesh)
  int fit_nodes = 12;                 ///< surface nodes nearest each gauge in its strain fit
  bool run = true;                    ///< false: write the files only
};

/// One solved mesh.
struct FeSolution {
  double element_size_m = 0;
  int layers = 0;
  int nodes = 0;
  Mat6 stiffness = Mat6::Zero();  ///< platform, at the origin
  Eigen::MatrixXd gauge_strain;   ///< G × 6, per unit wrench
  double seconds = 0;
  /// A sample of the mesh nodes (at most a few thousand) for a picture: position (m),
  /// displacement under a unit Fz (m/N) and the strain magnitude |ε| there (per N).
  std::vector<Eigen::Vector3d> sample_m, sample_u;
  std::vector<double> sample_strain;
};

struct FeCheck {
  bool ran = false;
  std::string note;                ///< what was written and how to run it, or what failed
  std::vector<FeSolution> meshes;  ///< first and refined mesh
  Mat6 model_stiffness = Mat6::Zero();
  Eigen::MatrixXd model_gauge_strain;
  std::vector<std::string> gauge_names;
  /// (gauge, axis) pairs whose model strain is ≥ 25 % of the largest gauge strain on that axis:
  /// the terms that carry the signal of that axis.
  std::vector<std::pair<int, int>> dominant;
};

/// Writes the body (gmsh .geo) and, when gmsh is installed, meshes it at two sizes and writes
/// the CalculiX decks; when ccx is installed too (and o.run), solves them and reads the platform
/// compliance and the grid-averaged gauge strains. Progress lines go to `progress` (may be null).
[[nodiscard]] FeCheck RunFeCheck(const DesignModel& m, const FeCheckOptions& o,
                                 std::ostream* progress);

/// Model against FE side by side: stiffness diagonal and dominant gauge strains with ratios
/// model/FE on both meshes, and the change between the meshes.
void PrintFeCheck(std::ostream& out, const FeCheck& c);
[[nodiscard]] nlohmann::json FeCheckJson(const FeCheck& c);

/// Largest |model/FE − 1| over the stiffness diagonal and the dominant gauge strains (refined
/// mesh); NaN when no FE solution exists.
[[nodiscard]] double WorstFeDeviation(const FeCheck& c);

}  // namespace ftstack::sim::design
