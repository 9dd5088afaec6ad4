#pragma once
// CollisionVoxels: the voxel model of paper 000 §3.3 (its Fig. 11) — a regular grid over the
// object's bounds whose voxels are marked in advance when they contain part of the object; a
// discrete edge point collides with the object when it lies in a marked voxel.

#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace kerf {

/// A voxel grid local to the object's bounding box (plus one voxel of margin on every side),
/// built once before the operation (paper 000 §3.3: "voxels containing a part of an object are
/// marked in advance to the operation"). A voxel is marked when its centre lies in a
/// tetrahedron of the mesh; it stores the region (layer) of that tetrahedron so that a layered
/// body gives each discrete edge point the material it is in. Queries allocate nothing.
class CollisionVoxels {
public:
  /// Marks the voxels of `mesh` with cubic voxels of edge `voxel_size` [m] > 0. The grid's lower
  /// corner is the mesh's lower bound minus one voxel, so a box whose sides are multiples of
  /// `voxel_size` has its faces exactly on voxel faces. `regions` names volume groups (layers);
  /// empty means one region (index 0) for the whole mesh. Throws std::invalid_argument for a bad
  /// size or a grid above `max_voxels` voxels, MeshError for an unknown region.
  CollisionVoxels(const TetMesh& mesh, double voxel_size, const std::vector<std::string>& regions = {},
                  long max_voxels = 50'000'000);

  /// Region index of the marked voxel containing `p`, or -1 when `p` is in no marked voxel
  /// (outside the grid counts as unmarked).
  [[nodiscard]] int region_at(const Eigen::Vector3d& p) const noexcept;
  [[nodiscard]] bool marked(const Eigen::Vector3d& p) const noexcept { return region_at(p) >= 0; }

  [[nodiscard]] double voxel_size() const { return m_size; }
  [[nodiscard]] const Eigen::Vector3i& dimensions() const { return m_dims; }
  [[nodiscard]] const Eigen::Vector3d& origin() const { return m_origin; }
  [[nodiscard]] long marked_count() const { return m_marked; }
  /// Memory held by the voxel labels [bytes].
  [[nodiscard]] std::size_t memory_bytes() const { return m_labels.size() * sizeof(std::int8_t); }

private:
  double m_size = 0.0;
  Eigen::Vector3d m_origin = Eigen::Vector3d::Zero();
  Eigen::Vector3i m_dims = Eigen::Vector3i::Zero();
  std::vector<std::int8_t> m_labels; ///< region index per voxel, -1 unmarked; x fastest
  long m_marked = 0;
};

} // namespace kerf
