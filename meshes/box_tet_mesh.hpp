#pragma once
// A structured tetrahedral mesh of a box, without gmsh: each of nx*ny*nz hexahedral cells is
// split into the 6 tetrahedra of the Kuhn (Freudenthal) subdivision, which is conforming
// across cells. Used for closed-form verification tests and as a gmsh-free fallback body.

#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>

namespace kerf {

/// Box [lower, upper] with nx by ny by nz cells (each >= 1). Physical groups: volume `body`;
/// surfaces `support` (z = lower.z), `top` (z = upper.z) and `sides` (the other four faces).
/// Every tetrahedron has positive volume (upper - lower).prod() / (6 nx ny nz).
TetMesh box_tet_mesh(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, int nx, int ny, int nz);

/// Splits a mesh into the two layers of paper 001 §6 by height: adds the volume groups
/// `layer_upper` (tetrahedra whose centroid lies above z = interface_z) and `layer_lower` (the
/// others). Exact when z = interface_z is a plane of element faces (a grid plane of a box mesh).
void add_height_layers(TetMesh& mesh, double interface_z);

} // namespace kerf
