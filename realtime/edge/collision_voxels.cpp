#include "realtime/edge/collision_voxels.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

CollisionVoxels::CollisionVoxels(const TetMesh& mesh, double voxel_size, const std::vector<std::string>& regions,
                                 long max_voxels)
    : m_size(voxel_size) {
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw std::invalid_argument("edge model: collision voxel size must be positive and finite");
  if (mesh.tets.rows() == 0) throw std::invalid_argument("edge model: collision voxels need a non-empty mesh");
  if (regions.size() > 127) throw std::invalid_argument("edge model: at most 127 regions in the collision voxels");
  const Eigen::Vector3d lower = mesh.nodes.colwise().minCoeff().transpose();
  const Eigen::Vector3d upper = mesh.nodes.colwise().maxCoeff().transpose();
  m_origin = lower - Eigen::Vector3d::Constant(m_size);
  const Eigen::Vector3d extent = (upper - m_origin) / m_size;
  long total = 1;
  for (int a = 0; a < 3; ++a) {
    m_dims[a] = static_cast<int>(std::ceil(extent[a] - 1e-9)) + 1;
    total *= m_dims[a];
    if (total > max_voxels)
      throw std::invalid_argument("edge model: collision voxel grid of size " + std::to_string(m_size) +
                                  " m over the object's bounds exceeds " + std::to_string(max_voxels) + " voxels");
  }
  m_labels.assign(static_cast<std::size_t>(total), std::int8_t{-1});

  Eigen::VectorXi tet_region;
  if (regions.empty()) tet_region = Eigen::VectorXi::Zero(mesh.tets.rows());
  else tet_region = tet_regions(mesh, regions);

  // Mark: every voxel centre inside a tetrahedron (barycentric coordinates all >= 0, with a
  // relative tolerance so that centres on shared faces are not lost between two elements).
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (tet_region[t] < 0) continue;
    const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0)).transpose();
    Eigen::Matrix3d edges;
    Eigen::Vector3d lo = a, hi = a;
    for (int k = 1; k < 4; ++k) {
      const Eigen::Vector3d v = mesh.nodes.row(mesh.tets(t, k)).transpose();
      edges.col(k - 1) = v - a;
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    const double det = edges.determinant();
    if (std::abs(det) <= 0.0) continue;
    const Eigen::Matrix3d inverse = edges.inverse();
    Eigen::Vector3i i0, i1;
    for (int a2 = 0; a2 < 3; ++a2) {
      // Voxel i has its centre at origin + (i + 1/2) h.
      i0[a2] = std::max(0, static_cast<int>(std::ceil((lo[a2] - m_origin[a2]) / m_size - 0.5)));
      i1[a2] = std::min(m_dims[a2] - 1, static_cast<int>(std::floor((hi[a2] - m_origin[a2]) / m_size - 0.5)));
    }
    for (int k = i0.z(); k <= i1.z(); ++k)
      for (int j = i0.y(); j <= i1.y(); ++j)
        for (int i = i0.x(); i <= i1.x(); ++i) {
          const Eigen::Vector3d centre = m_origin + m_size * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
          const Eigen::Vector3d b = inverse * (centre - a);
          constexpr double tol = 1e-12;
          if (b.minCoeff() < -tol || b.sum() > 1.0 + tol) continue;
          std::int8_t& label = m_labels[static_cast<std::size_t>(i + m_dims.x() * (j + static_cast<long>(m_dims.y()) * k))];
          if (label < 0) ++m_marked;
          if (label < 0 || tet_region[t] < label) label = static_cast<std::int8_t>(tet_region[t]);
        }
  }
}

int CollisionVoxels::region_at(const Eigen::Vector3d& p) const noexcept {
  const Eigen::Vector3d q = (p - m_origin) / m_size;
  if (!q.allFinite()) return -1;
  const double x = std::floor(q.x()), y = std::floor(q.y()), z = std::floor(q.z());
  if (x < 0.0 || y < 0.0 || z < 0.0 || x >= m_dims.x() || y >= m_dims.y() || z >= m_dims.z()) return -1;
  const long index = static_cast<long>(x) + m_dims.x() * (static_cast<long>(y) + static_cast<long>(m_dims.y()) * static_cast<long>(z));
  return m_labels[static_cast<std::size_t>(index)];
}

} // namespace kerf
