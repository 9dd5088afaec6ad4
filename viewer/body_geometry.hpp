#pragma once
// BodyGeometry: what the render thread draws of a body at one instant — its fine mesh (deformed
// and rest positions, tetrahedra or, for a surface-only model, triangles) and a wire-frame overlay
// of the model's own structure (spring network, voxel grid, discrete edge, crack). VTK-free.

#include <Eigen/Core>

#include <string>

namespace kerf {

struct BodyGeometry {
  Eigen::MatrixXd points;      ///< #P by 3 current positions [m]
  Eigen::MatrixXd rest;        ///< #P by 3 rest positions [m] (displacement = points - rest)
  Eigen::MatrixXi tets;        ///< #T by 4 (empty for a surface-only body)
  Eigen::MatrixXi triangles;   ///< #F by 3 (used when `tets` is empty), outward
  Eigen::MatrixXd overlay_points; ///< #Q by 3 [m]
  Eigen::MatrixXi overlay_lines;  ///< #L by 2 indices into overlay_points
  std::string status;          ///< one line about the model's state ("tears 1, pieces 2")
};

} // namespace kerf
