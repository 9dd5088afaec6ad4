#pragma once
// The network's tear carried into the fine tetrahedral mesh, paper 000 §2.2 (Fig. 5): the
// tetrahedra that cross the cell faces exposed by the division are divided along those faces
// and the pieces distributed to the sides.

#include "meshes/tet_mesh.hpp"
#include "realtime/springs/spring_network.hpp"

#include <vector>

namespace kerf {

/// A fine mesh split along the network's pieces.
struct TornTetMesh {
  TetMesh mesh;                  ///< rest positions; nodes duplicated per piece; volume group "body"
  std::vector<int> host_cell;    ///< per node: a cell of its piece that contains it (−1 outside the network)
  std::vector<int> piece;        ///< per tetrahedron: the network piece label it belongs to
};

/// Splits `mesh` (rest configuration, the one `net` was built on) along the network's pieces
/// (network_pieces): a tetrahedron over cells of one piece is kept whole; one over cells of
/// different pieces is clipped by every grid plane through it (exact tilings of the tetrahedron
/// by the plane-cut cases 1-3, 2-2 and those with vertices on the plane), and each part goes to
/// the piece of the cell holding its centroid. Nodes are shared within a piece and duplicated
/// across pieces, so each piece becomes its own connected component. Volumes add up to the
/// original's to round-off; every tetrahedron has positive volume. Allocates (not for `step`).
TornTetMesh split_tet_mesh(const TetMesh& mesh, const SpringNetwork& net);

} // namespace kerf
