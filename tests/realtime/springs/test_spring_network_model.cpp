// The model on the clay_pull setting: the network around the stylus, its supports and
// attachment, and the pull force from the three integrators.

#include "tests/realtime/springs/model_fixtures.hpp"

#include <gtest/gtest.h>

namespace kerf {
namespace {

TEST(SpringNetworkModel, BuildsAroundTheStylus) {
  const TetMesh mesh = test::clay_pull_mesh();
  const SpringNetworkModel model(mesh, test::clay_pull_setup(SpringIntegrator::symplectic_euler));
  const SpringNetwork& net = model.network();
  // Block side = smallest body extent (20 mm), N = 8: h = 2.5 mm, shifted into the body: x in
  // [10, 30] mm, y in [-10, 10] mm, z in [0, 20] mm — all 512 cells inside.
  EXPECT_NEAR(net.block.cell_size, 2.5e-3, 1e-15);
  EXPECT_NEAR(net.block.origin.x(), 0.01, 1e-12);
  EXPECT_NEAR(net.block.origin.z(), 0.0, 1e-12);
  EXPECT_EQ(net.cell_count(), 512);
  int base = 0, boundary = 0, free_top = 0;
  for (int p = 0; p < net.node_count; ++p) {
    const Eigen::Vector3d r = net.rest.col(p);
    const bool fixed = net.constraint[static_cast<std::size_t>(p)] == fix_all;
    if (r.z() < 1e-9) base += fixed;
    else if (std::abs(r.x() - 0.01) < 1e-9 || std::abs(r.x() - 0.03) < 1e-9 || std::abs(std::abs(r.y()) - 0.01) < 1e-9)
      boundary += fixed;
    else if (std::abs(r.z() - 0.02) < 1e-9 && !fixed) ++free_top;
  }
  EXPECT_EQ(base, 81);           // bonded base: 9 x 9 nodes
  EXPECT_EQ(boundary, 4 * 8 * 8); // block faces inside the body, above the base
  // Attached: nodes within r + h/2 = 3.25 mm of the tip centre (20, 0, 22) mm: the top-face
  // node under it and its four neighbours at 2.5 mm (distance √(2.5² + 2²) = 3.2 mm).
  EXPECT_EQ(model.attached_nodes(0), 5);
  EXPECT_EQ(free_top, 7 * 7 - 5);
}

TEST(SpringNetworkModel, PullForceFromEachIntegrator) {
  const TetMesh mesh = test::clay_pull_mesh();
  std::vector<double> final_force;
  for (const SpringIntegrator integrator : test::every_spring_integrator) {
    SpringNetworkModel model(mesh, test::clay_pull_setup(integrator));
    std::array<ToolState, 1> tool;
    std::array<ForceSample, 1> force;
    const double dt = 1e-3;
    // Pull up 0.5 mm at 5 mm/s, then hold 0.2 s.
    for (int k = 0; k <= 300; ++k) {
      tool[0].position = Eigen::Vector3d(0.02, 0.0, 0.022 + 5e-3 * dt * std::min(k, 100));
      model.step(tool, dt, force);
      ASSERT_TRUE(force[0].force.allFinite());
      EXPECT_FALSE(force[0].over_budget) << to_string(integrator) << " sample " << k;
      EXPECT_EQ(force[0].mode, InteractionMode::deformation_1);
    }
    // The body pulls the stylus back down.
    EXPECT_LT(force[0].force.z(), 0.0);
    // No sideways force (the set-up is symmetric about x = 20 mm), to what the integrators
    // resolve: the Newton tolerance (residual ≤ 10⁻⁵ k₁h = 4·10⁻⁶ N per node, 5 nodes on the
    // stylus, against a 2.2 N pull) and the single-precision force loops' round-off (ε = 6·10⁻⁸
    // over the stylus's cells): ~10⁻⁶ of the pull, so 10⁻⁵.
    EXPECT_NEAR(force[0].force.x(), 0.0, 1e-5 * std::abs(force[0].force.z())) << to_string(integrator);
    final_force.push_back(force[0].force.z());
  }
  // After the hold the dynamic integrators settle on the static equilibrium (η = 10 Pa s
  // damps them; the static solution is the independent value).
  EXPECT_NEAR(final_force[1], final_force[0], 0.02 * std::abs(final_force[0]));
  EXPECT_NEAR(final_force[2], final_force[0], 0.10 * std::abs(final_force[0]));
  EXPECT_NEAR(final_force[3], final_force[0], 0.02 * std::abs(final_force[0]));
}

TEST(SpringNetworkModel, BladePressesOnlyOnceItsEdgeArrives) {
  // The deformation phase of a cutting scene (potato_rect_cut's geometry: a bonded 40 x 20 x 15 mm
  // prism, a 30 mm edge across it at x = 20 mm, starting 1 mm above the top face, pressed down).
  // Independent expectations: no force before the edge reaches the surface (the gap); after it,
  // the body pushes the blade back (+z) with no net x or y force (the set-up is symmetric about
  // x = 20 mm and y = 0), the static force grows with the depth, and returns to zero when the
  // blade is withdrawn to the surface (elastic, quasi-static).
  const TetMesh mesh = box_tet_mesh({0.0, -0.01, 0.0}, {0.04, 0.01, 0.015}, 16, 8, 6);
  SpringNetworkSetup s = test::clay_pull_setup(SpringIntegrator::quasi_static);
  s.youngs_modulus = 3e6;
  s.styluses = {{Eigen::Vector3d(0.02, 0.0, 0.016), 0.0, BladeShape{.edge_direction = Eigen::Vector3d::UnitY(),
      .cutting_direction = -Eigen::Vector3d::UnitZ(),
      .edge_length = 0.03}}};
  SpringNetworkModel model(mesh, s);
  // The block covers the edge's 20 mm span in the body: h = 20 mm / 8; the first layer under the
  // edge is the top face's line x = 20 mm, y in [-10, 10] mm: 9 nodes.
  EXPECT_NEAR(model.network().block.cell_size, 2.5e-3, 1e-15);
  EXPECT_EQ(model.attached_nodes(0), 9);
  std::array<ToolState, 1> tool;
  std::array<ForceSample, 1> force;
  double last = 0.0;
  for (const double depth : {-0.5e-3, 0.0, 0.25e-3, 0.5e-3, 1.0e-3, 1.5e-3}) {
    tool[0].position = Eigen::Vector3d(0.02, 0.0, 0.015 - depth);
    model.step(tool, 1e-3, force);
    ASSERT_FALSE(force[0].over_budget) << depth;
    if (depth <= 0.0) {
      EXPECT_LT(force[0].force.norm(), 1e-9) << depth; // the rest state's round-off (4.6e-13 N)
      continue;
    }
    EXPECT_GT(force[0].force.z(), last) << depth;
    EXPECT_LT(std::abs(force[0].force.x()), 1e-6 * force[0].force.z()) << depth;
    EXPECT_LT(std::abs(force[0].force.y()), 1e-6 * force[0].force.z()) << depth;
    last = force[0].force.z();
  }
  tool[0].position = Eigen::Vector3d(0.02, 0.0, 0.015);
  model.step(tool, 1e-3, force);
  // Zero to the Newton tolerance (10⁻⁵ k₁ h = 2.3e-5 N per node, 9 attached nodes).
  EXPECT_LT(force[0].force.norm(), 9 * 2.3e-5);
}

} // namespace
} // namespace kerf
