#include "viewer/voxel_adapter.hpp"

#include "meshes/surface_mesh.hpp"

#include <cstdio>
#include <stdexcept>

namespace kerf {

VoxelAdapter::VoxelAdapter(const VoxelSurfaceCuttingModel& model, const TetMesh& mesh) : m_model(model) {
  SurfaceMesh surface = boundary_surface(mesh);
  if (surface.vertices.rows() != model.polygon_vertices().rows())
    throw std::invalid_argument("viewer: the voxel model's polygon surface has " +
                                std::to_string(model.polygon_vertices().rows()) + " vertices, the scene mesh's boundary " +
                                std::to_string(surface.vertices.rows()));
  m_rest = model.polygon_vertices();
  m_triangles = std::move(surface.triangles);
}

void VoxelAdapter::reserve(ModelState& state) const {
  state.points = Eigen::Matrix3Xd::Zero(3, m_rest.rows());
  state.rest = m_rest.transpose();
  state.cells.clear();
  state.point_count = 0;
  state.cell_count = 0;
}

void VoxelAdapter::capture(ModelState& state) const noexcept {
  const Eigen::MatrixXd& v = m_model.polygon_vertices();
  const Eigen::Index n = std::min(v.rows(), state.points.cols());
  state.points.leftCols(n) = v.topRows(n).transpose();
  state.point_count = static_cast<int>(n);
  const LocalVoxelGrid& grid = m_model.grid();
  const VoxelFrame& f = grid.frame();
  state.scalars[0] = grid.placed() && m_model.in_contact_episode() ? 1.0 : 0.0;
  for (int i = 0; i < 3; ++i) {
    state.scalars[1 + i] = f.origin[i];
    state.scalars[4 + i] = f.depth_axis[i];
    state.scalars[7 + i] = f.u_axis[i];
    state.scalars[10 + i] = f.v_axis[i];
  }
  state.scalars[13] = grid.cell_size();
  state.scalars[14] = grid.column_u();
  state.scalars[15] = grid.column_v();
  state.scalars[16] = grid.layer_top();
}

void VoxelAdapter::geometry(const ViewFrame& frame, BodyGeometry& out) {
  const ModelState& state = frame.model;
  out.rest = m_rest;
  out.points = state.point_count == m_rest.rows() ? Eigen::MatrixXd(state.points.leftCols(state.point_count).transpose())
                                                  : m_rest;
  out.tets.resize(0, 4);
  out.triangles = m_triangles;
  out.overlay_points.resize(0, 3);
  out.overlay_lines.resize(0, 2);
  const LocalVoxelGrid& grid = m_model.grid(); // cell counts only: fixed at construction
  const double moved = (out.points - out.rest).rowwise().norm().maxCoeff();
  char line[160];
  if (state.scalars[0] > 0.5) {
    // The grid's box in world space: w in [layer_top, layer_top + depth cells] h, a and b over the
    // grid's columns, mapped by x = origin + w d + a u + b v (VoxelFrame).
    const Eigen::Vector3d origin(state.scalars[1], state.scalars[2], state.scalars[3]);
    const Eigen::Vector3d d(state.scalars[4], state.scalars[5], state.scalars[6]);
    const Eigen::Vector3d u(state.scalars[7], state.scalars[8], state.scalars[9]);
    const Eigen::Vector3d v(state.scalars[10], state.scalars[11], state.scalars[12]);
    const double h = state.scalars[13];
    const std::array<int, 3> lower{static_cast<int>(state.scalars[16]), static_cast<int>(state.scalars[14]),
                                   static_cast<int>(state.scalars[15])};
    const std::array<int, 3> cells{grid.depth_cells(), grid.u_cells(), grid.v_cells()};
    // Grid lines on the box's faces: every cell boundary along each axis, on the two faces of
    // each of the other axes.
    std::vector<Eigen::Vector3d> p;
    auto world = [&](double w, double a, double b) { return Eigen::Vector3d(origin + w * h * d + a * h * u + b * h * v); };
    for (int axis = 0; axis < 3; ++axis) {
      const int s = (axis + 1) % 3, t = (axis + 2) % 3;
      for (int side_s = 0; side_s < 2; ++side_s)
        for (int k = 0; k <= cells[static_cast<std::size_t>(t)]; ++k) {
          std::array<double, 3> a{}, b{};
          a[static_cast<std::size_t>(axis)] = lower[static_cast<std::size_t>(axis)];
          b[static_cast<std::size_t>(axis)] = lower[static_cast<std::size_t>(axis)] + cells[static_cast<std::size_t>(axis)];
          a[static_cast<std::size_t>(s)] = b[static_cast<std::size_t>(s)] =
              lower[static_cast<std::size_t>(s)] + side_s * cells[static_cast<std::size_t>(s)];
          a[static_cast<std::size_t>(t)] = b[static_cast<std::size_t>(t)] = lower[static_cast<std::size_t>(t)] + k;
          p.push_back(world(a[0], a[1], a[2]));
          p.push_back(world(b[0], b[1], b[2]));
        }
    }
    out.overlay_points.resize(static_cast<Eigen::Index>(p.size()), 3);
    out.overlay_lines.resize(static_cast<Eigen::Index>(p.size() / 2), 2);
    for (std::size_t i = 0; i < p.size(); ++i) out.overlay_points.row(static_cast<Eigen::Index>(i)) = p[i].transpose();
    for (Eigen::Index l = 0; l < out.overlay_lines.rows(); ++l) out.overlay_lines.row(l) << 2 * l, 2 * l + 1;
    std::snprintf(line, sizeof line, "voxel grid %dx%dx%d of %.2f mm placed; surface moved up to %.2f mm", cells[0],
                  cells[1], cells[2], h * 1e3, moved * 1e3);
  } else {
    std::snprintf(line, sizeof line, "no voxel grid (no contact); surface moved up to %.2f mm", moved * 1e3);
  }
  out.status = line;
}

} // namespace kerf
