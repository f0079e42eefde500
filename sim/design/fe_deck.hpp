// Solid finite-element model of a design for gmsh and CalculiX: geometry, deck, result files.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "sim/design/design.hpp"

namespace ftstack::sim::design {

/// Mesh density of the solid model: hexahedra of 20 nodes (C3D20), about element_size_m long,
/// at least `min_layers` through each section side.
struct FeMeshSize {
  double element_size_m = 0.004;
  int min_layers = 2;
};

/// Divisions of a member of `length_m` (along, across width, across height).
[[nodiscard]] std::array<int, 3> MemberDivisions(const SolidMember& m, const FeMeshSize& s);

/// gmsh geometry (built-in kernel): every member a box extruded from its end-a section with
/// structured hexahedra, one physical volume "BODY" so that only solid elements are exported.
void WriteGmshGeometry(std::ostream& out, const DesignModel& m, const FeMeshSize& s);

/// Nodes of a mesh file written by gmsh in Abaqus format (id → coordinates, m).
[[nodiscard]] std::map<int, Eigen::Vector3d> ReadInpNodes(std::istream& in,
                                                          const std::string& origin);

/// Node ids of the rigid-body reference nodes: body k has translation node RefNode(k) and
/// rotation node RefNode(k) + 1, both at the origin.
[[nodiscard]] int RefNode(int body, int max_mesh_node);

/// Mesh nodes on the member end faces, per rigid body (0: the clamped ground).
[[nodiscard]] std::vector<std::vector<int>> EndFaceNodes(
    const DesignModel& m, const std::map<int, Eigen::Vector3d>& nodes);

/// The CalculiX deck: the mesh included from `mesh_file`, linear elastic material, every member's
/// end faces on their rigid bodies (ground: clamped; platform and stages: *RIGID BODY with a
/// reference and a rotation node at the origin), six static steps, one unit wrench component
/// each on the platform, printing the platform's displacement and the nodal strain.
void WriteCalculixDeck(std::ostream& out, const DesignModel& m,
                       const std::map<int, Eigen::Vector3d>& nodes, const std::string& mesh_file);

/// Platform displacement per unit wrench (6×6, column k under component k) from the .dat file.
[[nodiscard]] Mat6 ReadPlatformCompliance(std::istream& dat, int ref_node,
                                          const std::string& origin);

/// The i-th block of `name` ("TOSTRAIN", "DISP") of a .frd file per step: node → values.
[[nodiscard]] std::vector<std::map<int, std::vector<double>>> ReadFrdBlocks(
    std::istream& frd, const std::string& name, const std::string& origin);

/// Grid strain along each gauge (G × 6, column per step) from nodal strain tensors (xx yy zz xy
/// yz zx): d·ε·d at the `fit_nodes` surface nodes nearest the grid centre, fitted by a plane in
/// the face and read at the centre (the grid average where the strain varies linearly).
[[nodiscard]] Eigen::MatrixXd GaugeStrainFromNodes(
    const DesignModel& m, const std::map<int, Eigen::Vector3d>& nodes,
    const std::vector<std::map<int, std::vector<double>>>& strain_steps, int fit_nodes);

}  // namespace ftstack::sim::design
