#pragma once
// The clay block of clay_form.toml as the shape-forming tests build it directly (no scene file):
// material estimates of the scene, the edge's per-length parameters derived as edge_builder.cpp
// does (k' = E / (1 - ν²), F_s' = J_c, b' = η / (1 - ν²)), a coarse 4-cell spring network.

#include "realtime/edge/shape_forming_model.hpp"

namespace kerf::test {

inline ShapeFormingSetup clay_setup() {
  constexpr double E = 0.5e6, nu = 0.45; // clay_form.toml's estimates
  ShapeFormingSetup s;
  s.edge.blade.edge_direction = Eigen::Vector3d::UnitY();
  s.edge.blade.cutting_direction = -Eigen::Vector3d::UnitZ();
  s.edge.blade.edge_length = 0.050;
  s.edge.point_count = 100;
  s.edge.materials = {{E / (1.0 - nu * nu), 50.0, 10.0 / (1.0 - nu * nu)}};
  s.voxel_size = 6.25e-4;
  s.record_spacing = 6.25e-4;
  s.springs.youngs_modulus = E;
  s.springs.poisson_ratio = nu;
  s.springs.density = 1700.0;
  s.springs.damping = 10.0;
  s.springs.cells = 4; // a coarse network keeps the tests short (the composition is under test)
  s.springs.supports = {{"support", false}};
  s.springs.styluses = {{Eigen::Vector3d(0.008, 0.0, 0.022), 0.002}};
  return s;
}

} // namespace kerf::test
