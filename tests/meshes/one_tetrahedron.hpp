#pragma once
// The smallest mesh: the unit tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) in one volume
// group "body" (tag 1), for tests of readers, writers and views that need a mesh, not a body.

#include "meshes/tet_mesh.hpp"

namespace kerf::test {

inline TetMesh one_tetrahedron() {
  TetMesh mesh;
  mesh.nodes.resize(4, 3);
  mesh.nodes << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  mesh.tets.resize(1, 4);
  mesh.tets << 0, 1, 2, 3;
  mesh.volume_groups.push_back({"body", 1, {0}});
  return mesh;
}

} // namespace kerf::test
