#pragma once
// The viewer's reading of VoxelSurfaceCuttingModel (paper 002): its polygon surface as cutting
// lowers its vertices (§2.3 step 3), and the local voxel grid (§2.3 step 2) as the overlay while
// one is placed.

#include "realtime/voxel/voxel_surface_cutting_model.hpp"
#include "viewer/model_adapter.hpp"

namespace kerf {

/// ModelState layout: points = polygon vertices, rest = their rest positions; scalars[0] = grid
/// placed (0/1), [1..3] frame origin, [4..6] depth axis, [7..9] u axis, [10..12] v axis [m],
/// [13] cell size h [m], [14] first column along u, [15] along v, [16] first depth layer.
class VoxelAdapter final : public ModelAdapter {
public:
  /// `mesh` is the scene mesh; the model's polygon surface must be its boundary_surface (the
  /// model's builder makes it so; std::invalid_argument if the vertex counts differ).
  VoxelAdapter(const VoxelSurfaceCuttingModel& model, const TetMesh& mesh);

  void reserve(ModelState& state) const override;
  void capture(ModelState& state) const noexcept override;
  void geometry(const ViewFrame& frame, BodyGeometry& out) override;
  [[nodiscard]] std::string_view overlay_name() const override { return "voxel grid"; }

private:
  const VoxelSurfaceCuttingModel& m_model;
  Eigen::MatrixXd m_rest;      ///< #V by 3
  Eigen::MatrixXi m_triangles; ///< #F by 3
};

} // namespace kerf
