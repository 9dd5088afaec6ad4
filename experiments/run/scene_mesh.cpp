#include "experiments/run/scene_mesh.hpp"

#include "meshes/gmsh_io.hpp"
#include "meshes/mesh_error.hpp"

#include <sstream>

namespace kerf {

TetMesh scene_mesh(const Scene& scene) {
  const SceneGeometry& g = scene.geometry;
  TetMesh mesh;
  switch (g.kind) {
  case SceneGeometry::Kind::geo: mesh = mesh_geo(g.source, g.parameters, g.element_size); break;
  case SceneGeometry::Kind::stl: mesh = mesh_stl(g.source, g.element_size, g.stl_scale); break;
  case SceneGeometry::Kind::msh: mesh = read_msh(g.source); break;
  }
  const TetQualitySummary q = tet_quality_summary(mesh);
  if (!q.valid()) {
    std::ostringstream msg;
    msg << g.source.string() << ": the mesh has " << q.inverted << " inverted and " << q.degenerate
        << " degenerate tetrahedra (smallest signed volume " << q.min_volume
        << " m^3); expected every tetrahedron to have positive volume";
    throw MeshError(msg.str());
  }
  if (!mesh.find_volume_group("body") && g.kind != SceneGeometry::Kind::stl)
    throw MeshError(g.source.string() + ": no physical volume named \"body\"");
  return mesh;
}

} // namespace kerf
