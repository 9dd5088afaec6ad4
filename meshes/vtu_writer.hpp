#pragma once
// ParaView output through VTK (library kerf_meshes_vtk, kept apart so the realtime side never
// links VTK).

#include "meshes/tet_mesh.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace kerf {

/// Per-node or per-cell data to write beside the mesh: name and a #rows by k matrix.
using VtuField = std::pair<std::string, Eigen::MatrixXd>;

/// Writes the tetrahedra as a VTK XML unstructured grid (.vtu), atomically. Cell data always
/// includes `region` (index of the first volume group holding the cell), `signed_volume`,
/// `min_dihedral_deg` and `radius_ratio`; `point_data` rows match nodes, `cell_data` rows match
/// tets (MeshError otherwise).
void write_vtu(const TetMesh& mesh, const std::filesystem::path& vtu,
               const std::vector<VtuField>& point_data = {}, const std::vector<VtuField>& cell_data = {});

/// A .vtu writer as a value: write_vtu's signature. Code that must not link VTK (the model
/// builders, which the rig links) writes its meshes through the writer its caller passes, and
/// the research side passes `&write_vtu`.
using VtuWriter = void (*)(const TetMesh& mesh, const std::filesystem::path& vtu,
                           const std::vector<VtuField>& point_data, const std::vector<VtuField>& cell_data);

} // namespace kerf
