#pragma once

#include "experiments/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/tet_quality.hpp"

namespace kerf {

/// The scene's body as tetrahedra: its .geo meshed with the scene's parameters and element size,
/// its STL meshed, or its .msh read. Checked before anyone uses it: a mesh with inverted or
/// degenerate elements, or without a `body` volume, is a MeshError naming the geometry file and
/// the count and worst element.
TetMesh scene_mesh(const Scene& scene);

} // namespace kerf
