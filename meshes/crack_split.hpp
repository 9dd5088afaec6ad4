#pragma once
// Splitting a tetrahedral mesh along an internal surface, so that the two sides can separate: the
// crack path of a cohesive-zone model. Nodes on the surface are duplicated, one copy per side
// (gmsh's `Crack` plugin does the same on a physical surface); the surface's triangles become pairs
// of coincident faces, one on each side, which a cohesive interface joins until it fails
// (Ortiz & Pandolfi 1999, "Finite-deformation irreversible cohesive elements for three-dimensional
// crack-propagation analysis", Int. J. Numer. Meth. Engng 44, §2: the interface element is a pair
// of coincident surface elements).
//
// Which copies a node needs is decided topologically, not geometrically: the tetrahedra around a
// node are grouped into the sets connected through faces that are not on the surface. A node in
// the middle of the surface has two such sets (it is duplicated); a node on a crack front inside
// the body has one (it stays shared, so the crack closes there); a node where two surfaces meet
// may have more. This works for planar and curved surfaces, and for surfaces that end inside the
// body as well as ones that cut it through.

#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>

#include <string_view>
#include <vector>

namespace kerf {

/// The result of splitting a mesh along one of its internal surface groups.
struct CrackSplit {
  /// The split mesh. Tetrahedra keep their order and volume groups; nodes 0..#V−1 are the input's
  /// nodes, the copies follow. Surface groups keep their names, except the crack surface, which is
  /// replaced by `<name>+` (the faces of the side its triangles' normals point into) and `<name>-`
  /// (the other side's faces, wound the same way so both have the + normal).
  TetMesh mesh;
  /// #F by 3: triangle f of the crack surface as a face of the + side. Row order and vertex order
  /// are those of the input surface group's triangles.
  Eigen::MatrixXi plus_faces;
  /// #F by 3: the same triangle as a face of the − side; minus_faces(f, j) and plus_faces(f, j)
  /// were one node before the split (they are the same node at a crack front).
  Eigen::MatrixXi minus_faces;
  /// #V' entries: the input node each node of the split mesh is a copy of (itself for 0..#V−1).
  std::vector<int> original_node;
};

/// Splits `mesh` along the internal surface group `surface` (e.g. a scene's conformingly meshed
/// `cut_plane`). Throws MeshError if the group does not exist, is empty, or has a triangle that is
/// not an interior face shared by exactly two tetrahedra.
CrackSplit split_along_surface(const TetMesh& mesh, std::string_view surface);

/// Connected components of a tetrahedral mesh through shared faces: entry t is the component of
/// tetrahedron t (0, 1, …, in order of first appearance). A split mesh whose crack surface cuts the
/// body through has one more component than the input.
Eigen::VectorXi face_connected_components(const Eigen::MatrixXi& tets);

} // namespace kerf
