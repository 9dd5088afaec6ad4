#pragma once
// Shared fixtures of the voxel model tests: the sponge cube of paper 002 §3.2 and Table 1 as
// the builder reads it (docs/models.md, voxel), and a straight tool motion sampled at 1 kHz.

#include "meshes/box_tet_mesh.hpp"
#include "meshes/surface_mesh.hpp"
#include "realtime/voxel/voxel_surface_cutting_model.hpp"

#include <functional>

namespace kerf::test {

/// Surface of a cube of edge `edge` [m] with `cells` tetrahedral cells per edge: x in [0, edge],
/// y centred, z in [0, edge] (the axes of the sponge scenes).
inline SurfaceMesh cube_surface(double edge, int cells) {
  return boundary_surface(box_tet_mesh({0.0, -0.5 * edge, 0.0}, {edge, 0.5 * edge, edge}, cells, cells, cells));
}

/// Paper 002 Table 1 (sponge) as the builder reads it: k_e = 20 N/mm, b = 0.5 N s/mm, μ = 0.8,
/// critical forces 0.3 N (depth) and 0.1 N (cutting), advance 0.02 mm, grid 10 x 20 x 20; the
/// stick tip radius 0.02 mm (§3.2); E of Eq. (1) = 20 N/mm^2.
inline VoxelCuttingSetup sponge_setup() {
  VoxelCuttingSetup s;
  s.tool_radius = 0.02e-3;
  s.contact_stiffness = 2.0e4;
  s.damping = 500.0;
  s.friction_coefficient = 0.8;
  s.critical_force_depth = 0.3;
  s.critical_force_cutting = 0.1;
  s.advance_length = 0.02e-3;
  s.grid = {10, 20, 20};
  s.clip_modulus = 2.0e7;
  return s;
}

/// Moves the tool in a straight line from `from` to `to` at `speed` [m/s], one step per
/// millisecond, calling `after(state, sample)` after every step.
inline void move(ToolModel& model, const Eigen::Vector3d& from, const Eigen::Vector3d& to, double speed,
                 const std::function<void(const ToolState&, const ForceSample&)>& after = {}) {
  const double dt = 1e-3;
  const double length = (to - from).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(length / (speed * dt))));
  ToolState tool;
  tool.velocity = (to - from) / (steps * dt);
  ForceSample out;
  for (int k = 1; k <= steps; ++k) {
    tool.position = from + (to - from) * (static_cast<double>(k) / steps);
    tool.time += dt;
    model.step({&tool, 1}, dt, {&out, 1});
    if (after) after(tool, out);
  }
}

} // namespace kerf::test
