// The realtime contract (../shared/DESIGN.md): `step` allocates nothing. This program replaces
// the global operator new/delete and (outside sanitizer builds) glibc's malloc family with
// counting versions (the technique of tests/realtime/fracture/test_no_allocation.cpp), then
// steps the spring-network model with each integrator through a pull and hold on clay_pull, and
// the explicit one through a two-stylus pull that tears the network.

#include "tests/realtime/springs/model_fixtures.hpp"

#include "tests/realtime/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

using kerf::test::allocations;
using kerf::test::set_counting;

using namespace kerf;

namespace {
/// Steps `model` along `path(k)` (one position per stylus) for `samples` samples, counting.
template <class Path>
long allocations_while_stepping(SpringNetworkModel& model, int samples, Path path) {
  std::vector<ToolState> tools(static_cast<std::size_t>(model.tool_count()));
  std::vector<ForceSample> forces(tools.size());
  model.step(tools = path(0), 1e-3, forces); // first sample outside the count
  allocations = 0;
  set_counting(true);
  for (int k = 1; k <= samples; ++k) {
    const std::vector<ToolState>& next = path(k);
    for (std::size_t t = 0; t < tools.size(); ++t) tools[t] = next[t];
    model.step(tools, 1e-3, forces);
  }
  set_counting(false);
  return allocations.load();
}
} // namespace

TEST(RealtimeContract, SpringNetworkStepAllocatesNothing) {
  set_counting(true);
  ::operator delete(::operator new(16));
  set_counting(false);
  ASSERT_GE(allocations.load(), 1);
  // The aligned family is counted too (libgomp allocates its thread teams with aligned_alloc:
  // CHOLMOD's numeric factorisation did so once per supernode, docs/reliability.md).
  allocations = 0;
  set_counting(true);
  void* volatile aligned = std::aligned_alloc(64, 128);
  std::free(aligned);
  set_counting(false);
  ASSERT_GE(allocations.load(), 1);

  const TetMesh mesh = test::clay_pull_mesh();
  for (const SpringIntegrator integrator :
       {SpringIntegrator::symplectic_euler, SpringIntegrator::implicit_euler, SpringIntegrator::quasi_static,
        SpringIntegrator::linearly_implicit_euler}) {
    SpringNetworkModel model(mesh, test::clay_pull_setup(integrator));
    std::vector<std::vector<ToolState>> path(301, std::vector<ToolState>(1));
    for (int k = 0; k <= 300; ++k) path[static_cast<std::size_t>(k)][0].position = {0.02, 0.0, 0.022 + 5e-6 * std::min(k, 200)};
    EXPECT_EQ(allocations_while_stepping(model, 300, [&](int k) -> const std::vector<ToolState>& { return path[static_cast<std::size_t>(k)]; }), 0)
        << to_string(integrator);
  }
}

TEST(RealtimeContract, CompliantGraspAllocatesNothing) {
  // The compliant grasp (anchors on the top face, k = 1.9e9 N/m^3, a = 4 mm) through a pull and
  // hold, with every integrator.
  const TetMesh mesh = test::clay_pull_mesh();
  for (const SpringIntegrator integrator :
       {SpringIntegrator::symplectic_euler, SpringIntegrator::implicit_euler, SpringIntegrator::quasi_static,
        SpringIntegrator::linearly_implicit_euler}) {
    SpringNetworkSetup s = test::clay_pull_setup(integrator);
    s.styluses[0].grasp_stiffness = 1.9e9;
    s.styluses[0].grasp_disc_radius = 4e-3;
    SpringNetworkModel model(mesh, s);
    ASSERT_GT(model.anchored_nodes(0), 0);
    std::vector<std::vector<ToolState>> path(301, std::vector<ToolState>(1));
    for (int k = 0; k <= 300; ++k) path[static_cast<std::size_t>(k)][0].position = {0.02, 0.0, 0.022 + 5e-6 * std::min(k, 200)};
    EXPECT_EQ(allocations_while_stepping(model, 300, [&](int k) -> const std::vector<ToolState>& { return path[static_cast<std::size_t>(k)]; }), 0)
        << to_string(integrator);
  }
}

TEST(RealtimeContract, BladePressAllocatesNothing) {
  // The deformation phase of a cutting scene: a blade edge pressed 1.5 mm into a prism.
  const TetMesh mesh = box_tet_mesh({0.0, -0.01, 0.0}, {0.04, 0.01, 0.015}, 16, 8, 6);
  for (const SpringIntegrator integrator : {SpringIntegrator::symplectic_euler, SpringIntegrator::implicit_euler}) {
    SpringNetworkSetup s = test::clay_pull_setup(integrator);
    s.styluses = {{Eigen::Vector3d(0.02, 0.0, 0.016), 0.0, BladeShape{.edge_direction = Eigen::Vector3d::UnitY(),
        .cutting_direction = -Eigen::Vector3d::UnitZ(),
        .edge_length = 0.03}}};
    SpringNetworkModel model(mesh, s);
    std::vector<std::vector<ToolState>> path(301, std::vector<ToolState>(1));
    for (int k = 0; k <= 300; ++k) path[static_cast<std::size_t>(k)][0].position = {0.02, 0.0, 0.016 - 1e-5 * k};
    EXPECT_EQ(allocations_while_stepping(model, 300, [&](int k) -> const std::vector<ToolState>& { return path[static_cast<std::size_t>(k)]; }), 0)
        << to_string(integrator);
  }
}

TEST(RealtimeContract, TearingAllocatesNothing) {
  for (const SpringIntegrator integrator :
       {SpringIntegrator::symplectic_euler, SpringIntegrator::implicit_euler, SpringIntegrator::linearly_implicit_euler}) {
  // clay_tear: 60 x 20 x 20 mm on a table, styluses at x = 15 and 45 mm pulled 10 mm apart each.
  // The implicit integrator takes each split into its tear-ready pattern (no new analysis).
  const TetMesh mesh = box_tet_mesh({0.0, -0.01, 0.0}, {0.06, 0.01, 0.02}, 12, 4, 4);
  SpringNetworkSetup s = test::clay_pull_setup(integrator);
  s.supports = {{"support", true}};
  s.styluses = {{Eigen::Vector3d(0.015, 0.0, 0.022), 0.002}, {Eigen::Vector3d(0.045, 0.0, 0.022), 0.002}};
  s.tearing = true;
  s.tensile_limit = 50e3;
  SpringNetworkModel model(mesh, s);
  std::vector<std::vector<ToolState>> path(2001, std::vector<ToolState>(2));
  for (int k = 0; k <= 2000; ++k) {
    const double d = 5e-6 * k;
    path[static_cast<std::size_t>(k)][0].position = {0.015 - d, 0.0, 0.022};
    path[static_cast<std::size_t>(k)][1].position = {0.045 + d, 0.0, 0.022};
  }
  EXPECT_EQ(allocations_while_stepping(model, 2000, [&](int k) -> const std::vector<ToolState>& { return path[static_cast<std::size_t>(k)]; }), 0)
      << to_string(integrator);
  EXPECT_GT(model.tears(), 0) << to_string(integrator); // the tearing path was exercised while counting
  }
}
