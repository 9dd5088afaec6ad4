#pragma once
// The clay_pull and clay_tear settings (experiments/scenes/clay_pull.toml, clay_tear.toml) on
// gmsh-free box meshes (the tests' and bench_springs' one copy of them).

#include "meshes/box_tet_mesh.hpp"
#include "realtime/springs/spring_network_model.hpp"

#include <array>

namespace kerf::test {

/// Every integrator of the spring network (SpringIntegrator), for tests that run each.
inline constexpr std::array<SpringIntegrator, 4> every_spring_integrator{
    SpringIntegrator::quasi_static, SpringIntegrator::implicit_euler, SpringIntegrator::symplectic_euler,
    SpringIntegrator::linearly_implicit_euler};

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

/// clay_tear's 60 x 20 x 20 mm clay bar (the clay_pull material) on a table, on a box mesh of
/// h = 2.5 mm.
inline TetMesh clay_tear_mesh() { return box_tet_mesh({0.0, -0.01, 0.0}, {0.06, 0.01, 0.02}, 24, 8, 8); }

/// clay_tear: the bar's base on the table (sliding), styluses at x = 15 and 45 mm on the top face
/// grasping the nodes within 7.5 mm; the network of 12 cells along the bar (h = 5 mm) tears at
/// the cohesive strength, 50 kPa.
inline SpringNetworkSetup clay_tear_setup(SpringIntegrator integrator) {
  SpringNetworkSetup s = clay_pull_setup(integrator);
  s.supports = {{"support", true}};
  s.styluses = {{Eigen::Vector3d(0.015, 0.0, 0.022), 0.002}, {Eigen::Vector3d(0.045, 0.0, 0.022), 0.002}};
  s.cells = 12;
  s.grasp_radius = 0.0075;
  s.tearing = true;
  s.tensile_limit = 50e3;
  return s;
}

} // namespace kerf::test
