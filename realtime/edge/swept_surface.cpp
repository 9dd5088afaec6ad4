#include "realtime/edge/swept_surface.hpp"

#include <cmath>
#include <stdexcept>

namespace kerf {

SweptSurface sweep_edge(std::span<const Eigen::Vector3d> centres, const Eigen::Vector3d& edge_direction,
                        double edge_length) {
  if (centres.size() < 2) throw std::invalid_argument("swept surface: at least two edge positions are needed");
  if (std::abs(edge_direction.norm() - 1.0) > 1e-9) throw std::invalid_argument("swept surface: edge direction must be a unit vector");
  if (!(edge_length > 0.0) || !std::isfinite(edge_length)) throw std::invalid_argument("swept surface: edge length must be positive");
  const auto n = static_cast<Eigen::Index>(centres.size());
  SweptSurface s;
  s.vertices.resize(2 * n, 3);
  s.triangles.resize(2 * (n - 1), 3);
  const Eigen::Vector3d half = 0.5 * edge_length * edge_direction;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!centres[static_cast<std::size_t>(k)].allFinite()) throw std::invalid_argument("swept surface: non-finite edge position");
    s.vertices.row(2 * k) = (centres[static_cast<std::size_t>(k)] - half).transpose();
    s.vertices.row(2 * k + 1) = (centres[static_cast<std::size_t>(k)] + half).transpose();
  }
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    const int a0 = static_cast<int>(2 * k), b0 = a0 + 1, a1 = a0 + 2, b1 = a0 + 3;
    s.triangles.row(2 * k) << a0, b0, b1;
    s.triangles.row(2 * k + 1) << a0, b1, a1;
  }
  return s;
}

} // namespace kerf
