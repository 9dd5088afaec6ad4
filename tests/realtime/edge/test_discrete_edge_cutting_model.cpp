// Paper 000 §3.1 discrete-edge cutting force: each expected value below is the closed form of
// the model's own definition (stiffness x penetration, drag x speed, the shear cap, Coulomb's
// limit), evaluated independently of the code under test, on a box whose faces lie on voxel faces.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

namespace {

// Body: 40 x 20 x 15 mm box, base z = 0, y centred (as potato_rect_cut). 1 mm voxels: every
// face of the box is a voxel face, so contact starts exactly on the surface.
TetMesh body() { return box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5); }
constexpr double top = 0.015;

EdgeMaterial material(double stiffness_per_length, double shear_per_length, double drag_per_length = 0.0) {
  return {stiffness_per_length, shear_per_length, drag_per_length};
}

DiscreteEdgeSetup setup(double length, int k, EdgeMaterial m, double mu = 0.0) {
  DiscreteEdgeSetup s;
  s.blade.edge_length = length;
  s.point_count = k;
  s.materials = {m};
  s.friction_coefficient = mu;
  s.channel_capture_width = 1e-4;
  return s;
}

/// Moves the edge centre in straight steps of `step` [m] from `from` to `to`, returning the
/// last sample. Velocity is `velocity` throughout.
ForceSample move(DiscreteEdgeCuttingModel& model, const Eigen::Vector3d& from, const Eigen::Vector3d& to, double step,
                 const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero()) {
  const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / step)));
  ForceSample out;
  for (int i = 1; i <= n; ++i) {
    ToolState tool;
    tool.position = from + (to - from) * (static_cast<double>(i) / n);
    tool.velocity = velocity;
    model.step({&tool, 1}, 1e-3, {&out, 1});
  }
  return out;
}

} // namespace

TEST(DiscreteEdge, ForceOnStiffBodyIsStiffnessTimesPenetrationPerPoint) {
  // A 10 mm edge, fully over the top face, pressed 0.2 mm in; shear limit far above the load.
  const double k_per_length = 1e6, depth = 2e-4, length = 0.010;
  const int k_points = 10;
  DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(length, k_points, material(k_per_length, 1e9)));
  const ForceSample out = move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, top - depth}, 1e-5);
  // Each point: f = k δ with k = k' L / K (paper 000 §3.1, the stiffness coefficient).
  const double k_point = k_per_length * length / k_points;
  EXPECT_DOUBLE_EQ(model.point_stiffness(), k_point);
  for (const auto& p : model.points()) {
    EXPECT_TRUE(p.in_contact);
    EXPECT_NEAR(p.force.z(), k_point * depth, 1e-9 * k_point * depth);
    EXPECT_NEAR(p.relaxed.z(), top, 1e-12);
  }
  EXPECT_NEAR(out.force.z(), k_per_length * length * depth, 1e-9 * k_per_length * length * depth);
  EXPECT_NEAR(out.force.x(), 0.0, 1e-12);
  EXPECT_EQ(out.mode, InteractionMode::deformation_1);
}

TEST(DiscreteEdge, ViscousDragScalesWithSpeed) {
  // Drag f = -b' L v while the edge is in the object (paper 000 §3.1): at rest inside, then
  // two speeds across the blade; the elastic part is the same, the difference is the drag.
  const double b_per_length = 50.0, length = 0.010;
  double fx[3];
  const double speeds[3] = {0.0, 0.01, 0.03};
  for (int s = 0; s < 3; ++s) {
    DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(length, 8, material(1e6, 1e9, b_per_length)));
    const ForceSample out = move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, top - 1e-4}, 1e-5,
                                 Eigen::Vector3d(speeds[s], 0.0, 0.0));
    fx[s] = out.force.x();
  }
  EXPECT_NEAR(fx[0], 0.0, 1e-12);
  EXPECT_NEAR(fx[1], -b_per_length * length * speeds[1], 1e-12);
  EXPECT_NEAR(fx[2] / fx[1], speeds[2] / speeds[1], 1e-12);
}

TEST(DiscreteEdge, CuttingResistanceCapsTheForceAtTheShearLimit) {
  // Pressed 5 mm in: k δ = 1e6 * 1e-3 / 10 * 5e-3 = 0.5 N per point far above F_s = 200 N/m *
  // 1 mm = 0.2 N: every point is at the cap, the total is F_s' L = 2 N, and the cut reached
  // δ - F_s / k (the relaxed points advanced by the destroyed material).
  const double k_per_length = 1e6, shear = 200.0, length = 0.010, depth = 5e-3;
  DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(length, 10, material(k_per_length, shear)));
  ForceSample out = move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, top - depth}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::cutting);
  EXPECT_NEAR(out.force.z(), shear * length, 1e-9);
  for (const auto& p : model.points()) EXPECT_LE(p.force.norm(), model.point_shear_limit() * (1 + 1e-12));
  const double kept = shear * (length / 10) / (k_per_length * length / 10);
  EXPECT_NEAR(out.crack_extent, depth - kept, 1e-9);
  // Retreat inside the cut: the force falls linearly (deformation-2), then only drag (none here).
  out = move(model, {0.020, 0.0, top - depth}, {0.020, 0.0, top - depth + 0.5 * kept}, 1e-6);
  EXPECT_EQ(out.mode, InteractionMode::deformation_2);
  EXPECT_NEAR(out.force.z(), 0.5 * shear * length, 1e-9);
  out = move(model, {0.020, 0.0, top - depth + 0.5 * kept}, {0.020, 0.0, top - 1e-3}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::deformation_2);
  EXPECT_NEAR(out.force.norm(), 0.0, 1e-15);
  out = move(model, {0.020, 0.0, top - 1e-3}, {0.020, 0.0, top + 1e-3}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::no_contact);
  // Back down the same cut: no new surface contact; the material starts at the cut's front.
  out = move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, top - 1e-3}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::deformation_2);
  EXPECT_NEAR(out.force.norm(), 0.0, 1e-15);
  out = move(model, {0.020, 0.0, top - 1e-3}, {0.020, 0.0, top - depth - 1e-3}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::cutting);
  EXPECT_NEAR(out.force.z(), shear * length, 1e-9);
}

TEST(DiscreteEdge, ForceConvergesInPointCount) {
  // A 12 mm edge centred at y = 6.7 mm hangs over the side y = 10 mm: contact length
  // l = 10 - 0.7 = 9.3 mm. Closed forms: deformation k' l δ, cutting F_s' l. The midpoint rule
  // errs by at most one piece at the end: |F_K - F| <= k' δ L / K, falling with K.
  const double k_per_length = 1e6, shear = 200.0, length = 0.012, centre_y = 0.0067, l = 0.0093;
  const double depth = 1e-4;
  double previous_error = 1e300;
  for (int k : {4, 16, 64, 256, 1024}) {
    DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(length, k, material(k_per_length, shear)));
    const ForceSample pressed = move(model, {0.020, centre_y, top + 1e-3}, {0.020, centre_y, top - depth}, 1e-5);
    const double error = std::abs(pressed.force.z() - k_per_length * l * depth);
    EXPECT_LE(error, k_per_length * depth * length / k * (1 + 1e-9)) << "K = " << k;
    EXPECT_LE(error, previous_error) << "K = " << k;
    previous_error = error;
    const ForceSample cut = move(model, {0.020, centre_y, top - depth}, {0.020, centre_y, top - 0.003}, 1e-5);
    EXPECT_LE(std::abs(cut.force.z() - shear * l), shear * length / k * (1 + 1e-9)) << "K = " << k;
  }
  EXPECT_LT(previous_error, 0.002 * k_per_length * l * depth);
}

TEST(DiscreteEdge, FrictionAlongTheEdgeIsBoundedByCoulomb) {
  // Pressed in by δ, then slid along its own axis: the axial force rises elastically and then
  // stays at μ times the normal force (non-destructive: no cutting, nothing destroyed).
  const double k_per_length = 1e6, length = 0.010, depth = 1e-4, mu = 0.3;
  DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(length, 10, material(k_per_length, 1e9), mu));
  move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, top - depth}, 1e-5);
  const ForceSample out = move(model, {0.020, 0.0, top - depth}, {0.020, 0.002, top - depth}, 1e-6);
  const double normal = k_per_length * length * depth;
  EXPECT_NEAR(out.force.z(), normal, 1e-9 * normal);
  EXPECT_NEAR(out.force.y(), -mu * normal, 1e-9 * normal);
  EXPECT_EQ(out.mode, InteractionMode::deformation_1);
}

TEST(DiscreteEdge, LayersGiveEachPointItsRegionsShearLimit) {
  // Upper layer above z = 9 mm with F_s' = 500 N/m, lower 200 N/m: a cut force of F_s' L in each.
  TetMesh mesh = body();
  add_height_layers(mesh, 0.009);
  DiscreteEdgeSetup s = setup(0.010, 10, material(1e6, 500.0));
  s.materials.push_back(material(1e6, 200.0));
  DiscreteEdgeCuttingModel model(CollisionVoxels(mesh, 1e-3, {"layer_upper", "layer_lower"}), s);
  ForceSample out = move(model, {0.020, 0.0, top + 1e-3}, {0.020, 0.0, 0.012}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::cutting);
  EXPECT_NEAR(out.force.z(), 500.0 * 0.010, 1e-9);
  out = move(model, {0.020, 0.0, 0.012}, {0.020, 0.0, 0.006}, 1e-5);
  EXPECT_EQ(out.mode, InteractionMode::cutting);
  EXPECT_NEAR(out.force.z(), 200.0 * 0.010, 1e-9);
}

TEST(DiscreteEdge, OutsideTheVoxelsNoForceAndBadInputIsRefused) {
  DiscreteEdgeCuttingModel model(CollisionVoxels(body(), 1e-3), setup(0.010, 10, material(1e6, 200.0, 10.0)));
  ForceSample out = move(model, {0.020, 0.0, 0.030}, {0.020, 0.0, top + 1e-4}, 1e-4, {0.0, 0.0, -0.01});
  EXPECT_EQ(out.mode, InteractionMode::no_contact);
  EXPECT_EQ(out.force.norm(), 0.0);
  ToolState bad;
  bad.position = {std::nan(""), 0.0, 0.0};
  model.step({&bad, 1}, 1e-3, {&out, 1});
  EXPECT_TRUE(out.force.allFinite());
  EXPECT_EQ(model.non_finite_count(), 1);
  EXPECT_THROW(DiscreteEdgeCuttingModel(CollisionVoxels(body(), 1e-3), setup(0.010, 0, material(1e6, 200.0))),
               std::invalid_argument);
  EXPECT_THROW(DiscreteEdgeCuttingModel(CollisionVoxels(body(), 1e-3), setup(0.010, 4, material(0.0, 200.0))),
               std::invalid_argument);
  EXPECT_THROW(CollisionVoxels(body(), 0.0), std::invalid_argument);
  EXPECT_THROW(CollisionVoxels(body(), 1e-7), std::invalid_argument); // 4e11 voxels: refused
}

TEST(CollisionVoxels, MarksExactlyTheBoxAndStaysLocalToItsBounds) {
  // 40 x 20 x 15 mm at 1 mm: 12000 voxels inside, the grid one voxel wider on every side.
  const CollisionVoxels v(body(), 1e-3);
  EXPECT_EQ(v.marked_count(), 40 * 20 * 15);
  EXPECT_EQ(v.dimensions(), Eigen::Vector3i(42, 22, 17));
  EXPECT_TRUE(v.marked({0.0005, -0.0095, 0.0005}));
  EXPECT_FALSE(v.marked({0.0005, -0.0095, 0.0155}));
  EXPECT_FALSE(v.marked({1.0, 0.0, 0.0}));
}
