#pragma once
// Tests that run the scene-level reference on a coarse gmsh-free box (meshes/box_tet_mesh.hpp)
// give it the grasp surface a scene's grasping stylus needs (scene_mesh.hpp: `grasp<k>`): a box
// cannot conform to the disc, so the group is the `top` triangles whose centroids lie within the
// stylus's grasp radius of the point under its start (at least the nearest one). A gmsh mesh of
// the scene (scene_mesh) carries the disc itself.

#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"

#include <limits>
#include <stdexcept>

namespace kerf::test {

inline void add_grasp_groups_to_box(const Scene& scene, TetMesh& mesh) {
  const SurfaceGroup* top = mesh.find_surface_group("top");
  if (top == nullptr) throw std::invalid_argument("add_grasp_groups_to_box: the mesh has no 'top' group");
  int k = 0;
  for (const Tool& tool : scene.tools) {
    if (tool.kind != Tool::Kind::sphere || !tool.grasp_radius) continue;
    SurfaceGroup g;
    g.name = grasp_surface_name(++k);
    std::vector<Eigen::Index> rows;
    Eigen::Index nearest = -1;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < top->triangles.rows(); ++f) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int v = 0; v < 3; ++v) centroid += mesh.nodes.row(top->triangles(f, v)).transpose() / 3.0;
      const double d = (centroid.head<2>() - tool.trajectory.start.head<2>()).norm();
      if (d <= *tool.grasp_radius) rows.push_back(f);
      if (d < nearest_distance) nearest_distance = d, nearest = f;
    }
    if (rows.empty()) rows.push_back(nearest);
    g.triangles.resize(static_cast<Eigen::Index>(rows.size()), 3);
    for (std::size_t i = 0; i < rows.size(); ++i) g.triangles.row(static_cast<Eigen::Index>(i)) = top->triangles.row(rows[i]);
    mesh.surface_groups.push_back(std::move(g));
  }
}

} // namespace kerf::test
