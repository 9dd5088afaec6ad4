#pragma once
// The clay_pull setting (experiments/scenes/clay_pull.toml) on a gmsh-free box mesh.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/springs/spring_network_model.hpp"

namespace kerf::test {

/// 40 x 40 x 20 mm clay block (E = 0.5 MPa, ν = 0.45, ρ = 1700 kg/m^3, η = 10 Pa s, the scene's
/// estimates), base bonded, a 2 mm stylus touching the centre of the top face.
inline TetMesh clay_pull_mesh() { return box_tet_mesh({0.0, -0.02, 0.0}, {0.04, 0.02, 0.02}, 8, 8, 4); }

inline SpringNetworkSetup clay_pull_setup(SpringIntegrator integrator) {
  SpringNetworkSetup s;
  s.youngs_modulus = 0.5e6;
  s.poisson_ratio = 0.45;
  s.density = 1700.0;
  s.damping = 10.0;
  s.integrator = integrator;
  s.supports = {{"support", false}};
  s.styluses = {{Eigen::Vector3d(0.02, 0.0, 0.022), 0.002}};
  return s;
}

} // namespace kerf::test
