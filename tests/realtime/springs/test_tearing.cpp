// Tearing (paper 000 §2.2) on the clay_tear setting: two styluses pull a clay bar apart until the
// network separates into two pieces; the tear carried into the fine mesh gives two components whose
// volumes add up to the original (an exact tiling: volume is conserved), with no inverted
// tetrahedron, and the mode is deformation-1 until the tearing sample, rupture on it.

#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/torn_tet_mesh.hpp"
#include "realtime/springs/vertex_tearing.hpp"
#include "tests/realtime/springs/model_fixtures.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <numeric>

namespace kerf {
namespace {

/// Connected components of a tetrahedral mesh (tetrahedra sharing a node), with their volumes.
std::vector<double> component_volumes(const TetMesh& mesh) {
  std::vector<int> parent(static_cast<std::size_t>(mesh.nodes.rows()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&parent](int a) {
    while (parent[static_cast<std::size_t>(a)] != a) a = parent[static_cast<std::size_t>(a)];
    return a;
  };
  for (int t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 1; k < 4; ++k) parent[static_cast<std::size_t>(find(mesh.tets(t, k)))] = find(mesh.tets(t, 0));
  std::map<int, double> volume;
  for (int t = 0; t < mesh.tets.rows(); ++t) {
    const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(mesh.tets(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(mesh.tets(t, 2)).transpose();
    const Eigen::Vector3d d = mesh.nodes.row(mesh.tets(t, 3)).transpose();
    const double v = (b - a).dot((c - a).cross(d - a)) / 6.0;
    EXPECT_GT(v, 0.0) << "tetrahedron " << t;
    volume[find(mesh.tets(t, 0))] += v;
  }
  std::vector<double> out;
  for (const auto& [root, v] : volume) out.push_back(v);
  return out;
}

/// Smallest signed volume of the torn mesh's tetrahedra with its nodes at `nodes` (#V by 3).
double smallest_volume(const TetMesh& mesh, const Eigen::MatrixXd& nodes) {
  double smallest = INFINITY;
  for (int t = 0; t < mesh.tets.rows(); ++t) {
    const Eigen::Vector3d a = nodes.row(mesh.tets(t, 0)).transpose();
    const Eigen::Vector3d b = nodes.row(mesh.tets(t, 1)).transpose();
    const Eigen::Vector3d c = nodes.row(mesh.tets(t, 2)).transpose();
    const Eigen::Vector3d d = nodes.row(mesh.tets(t, 3)).transpose();
    smallest = std::min(smallest, (b - a).dot((c - a).cross(d - a)) / 6.0);
  }
  return smallest;
}

TEST(Tearing, ClayTearSplitsIntoTwoPiecesThatKeepTheVolume) {
  // clay_tear (experiments/scenes/clay_tear.toml): 60 x 20 x 20 mm clay bar on a table (sliding
  // base), styluses at x = 15 and 45 mm on the top face grasping the nodes within 7.5 mm, pulled
  // apart at 5 mm/s each; the network (12 cells per side, h = 5 mm) tears at the cohesive
  // strength 50 kPa, stepped by implicit Euler.
  const TetMesh mesh = test::clay_tear_mesh();
  const SpringNetworkSetup s = test::clay_tear_setup(SpringIntegrator::implicit_euler);
  SpringNetworkModel model(mesh, s);
  ASSERT_NEAR(model.network().block.cell_size, 0.005, 1e-15);
  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> forces;
  int rupture_sample = -1;
  for (int k = 0; k <= 2000 && rupture_sample < 0; ++k) {
    const double d = 5e-6 * k;
    tools[0].position = {0.015 - d, 0.0, 0.022};
    tools[1].position = {0.045 + d, 0.0, 0.022};
    model.step(tools, 1e-3, forces);
    for (const ForceSample& f : forces) ASSERT_TRUE(f.force.allFinite()) << "sample " << k;
    if (forces[0].mode == InteractionMode::rupture) {
      rupture_sample = k;
      EXPECT_EQ(forces[1].mode, InteractionMode::rupture);
    } else {
      EXPECT_EQ(forces[0].mode, InteractionMode::deformation_1) << "sample " << k;
      EXPECT_EQ(forces[1].mode, InteractionMode::deformation_1) << "sample " << k;
      EXPECT_EQ(model.pieces(), 1) << "sample " << k;
    }
  }
  ASSERT_GE(rupture_sample, 0) << "no tear after " << model.tears() << " vertex splits";
  EXPECT_EQ(model.pieces(), 2);
  // Before the tear the styluses pulled the bar apart: each felt the bar pulling it back.
  // After it each piece follows its stylus freely: one more sample and the forces vanish
  // compared with the pull (the pieces only keep their damped elastic recoil).

  const TornTetMesh torn = split_tet_mesh(mesh, model.network());
  const std::vector<double> volumes = component_volumes(torn.mesh);
  ASSERT_EQ(volumes.size(), 2u);
  // An exact tiling of the original bar: the volumes add up to its closed-form volume.
  const double original = 0.06 * 0.02 * 0.02;
  EXPECT_NEAR(std::accumulate(volumes.begin(), volumes.end(), 0.0), original, 1e-9 * original);
  EXPECT_NEAR(mesh_volume(mesh), original, 1e-9 * original);
  // No inverted tetrahedron at rest (component_volumes checks each) nor in the deformed state
  // at the tearing sample (the torn mesh embedded in the torn network).
  const NetworkEmbedding embedding(model.network(), torn.mesh.nodes, EmbeddingScheme::trilinear, &torn.host_cell);
  Eigen::MatrixXd deformed(torn.mesh.nodes.rows(), 3);
  embedding.apply(model.network(), model.positions(), deformed);
  EXPECT_GT(smallest_volume(torn.mesh, deformed), 0.0);
}

TEST(Tearing, VertexStressesAreTheSumsOfTheCellStressesOnATornNetwork) {
  // VertexTearing sums each node's cell stresses with every spring's term computed once for the
  // cells that share it; the second method is cell_stress cell by cell (the same numbers, to the
  // bit). On clay_tear's network torn part way (its copies share no spring with their
  // originals' other cells), through further splits (the sharing updated split by split).
  const TetMesh mesh = test::clay_tear_mesh();
  SpringNetworkModel model(mesh, test::clay_tear_setup(SpringIntegrator::implicit_euler));
  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> forces;
  for (int k = 0; k <= 2000 && model.tears() < 20; ++k) {
    tools[0].position = {0.015 - 5e-6 * k, 0.0, 0.022};
    tools[1].position = {0.045 + 5e-6 * k, 0.0, 0.022};
    model.step(tools, 1e-3, forces);
  }
  ASSERT_GE(model.tears(), 20);
  SpringNetwork net = model.network();
  Eigen::Matrix3Xd x = model.positions();
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  // The right half moved 1 mm further along the bar, so that the cells right of the middle
  // plane are stretched by a fifth and its vertices split, one a call.
  for (int p = 0; p < net.node_count; ++p)
    if (net.rest(0, p) > 0.031) x(0, p) += 1e-3;
  // The vertices split already (a copy and its original share a rest position) split no more.
  std::vector<std::uint8_t> excluded(static_cast<std::size_t>(net.node_capacity()), 0);
  for (int p = 0; p < net.node_count; ++p)
    for (int q = p + 1; q < net.node_count; ++q)
      if (net.rest.col(p) == net.rest.col(q)) excluded[static_cast<std::size_t>(p)] = excluded[static_cast<std::size_t>(q)] = 1;
  VertexTearing tearing(net, 50e3);
  int splits = 0;
  for (int call = 0; call < 6; ++call) {
    const SpringNetwork before = net;
    const bool split = tearing.tear(net, x, v, excluded);
    splits += split ? 1 : 0;
    std::vector<Eigen::Matrix3d> expected(static_cast<std::size_t>(before.node_count), Eigen::Matrix3d::Zero());
    Eigen::Matrix<double, 3, 8> xc;
    for (const auto& nodes : before.cell_nodes) {
      for (int a = 0; a < 8; ++a) xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
      const Eigen::Matrix3d sigma = cell_stress(before, xc);
      for (const int id : nodes) expected[static_cast<std::size_t>(id)] += sigma;
    }
    for (int p = 0; p < before.node_count; ++p)
      for (int e = 0; e < 9; ++e)
        ASSERT_EQ(tearing.cell_stress_sum(p).data()[e], expected[static_cast<std::size_t>(p)].data()[e]) << "call " << call << ", node " << p;
  }
  EXPECT_GE(splits, 3) << "largest vertex stress " << tearing.last_max_stress() << " Pa"; // the sharing was updated after splits, not only built
}

/// Splits node `original` the way a tear does: the cells whose centre lies on the positive side
/// of `normal` through it take a new copy. Returns the copy, or -1 if one side holds no cell.
int split_by_hand(SpringNetwork& net, int original, const Eigen::Vector3d& normal) {
  const int copy = net.node_count;
  const auto moves = [&](int c) {
    const Eigen::Vector3d centre =
        net.block.origin + (net.cell_index[static_cast<std::size_t>(c)].cast<double>() + Eigen::Vector3d::Constant(0.5)) * net.block.cell_size;
    return (centre - net.rest.col(original)).dot(normal) > 0.0;
  };
  int moved = 0, staying = 0;
  for (int c = 0; c < net.cell_count(); ++c)
    for (const int id : net.cell_nodes[static_cast<std::size_t>(c)])
      if (id == original) (moves(c) ? moved : staying) += 1;
  if (moved == 0 || staying == 0) return -1;
  for (int c = 0; c < net.cell_count(); ++c)
    for (int& id : net.cell_nodes[static_cast<std::size_t>(c)])
      if (id == original && moves(c)) id = copy;
  net.rest.col(copy) = net.rest.col(original);
  ++net.node_count;
  return copy;
}

void expect_equal_springs(const SpringNetwork& a, const SpringNetwork& b, const std::string& where) {
  ASSERT_EQ(a.springs.count, b.springs.count) << where;
  for (int i = 0; i < a.springs.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ASSERT_EQ(a.springs.a[k], b.springs.a[k]) << where << ", spring " << i;
    ASSERT_EQ(a.springs.b[k], b.springs.b[k]) << where << ", spring " << i;
    ASSERT_EQ(a.springs.k[k], b.springs.k[k]) << where << ", spring " << i; // bit-identical sums
    ASSERT_EQ(a.springs.rest[k], b.springs.rest[k]) << where << ", spring " << i;
  }
}

// The second method is merge_springs itself: the springs rebuilt from every cell after each
// split, which merge_springs_after_split must give to the bit (the same order, the same sums).
TEST(MergeSpringsAfterSplit, GivesWhatAFullMergeGivesAfterEverySplit) {
  const double h = 2.5e-3;
  SpringNetwork incremental = test::full_block(4, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness);
  SpringNetwork full = incremental;
  // Interior, face, edge and corner nodes split along the three axes and a diagonal, some of
  // them twice (a copy's own cells split again), so that edges shared by 1-4 cells change.
  const Eigen::Vector3d normals[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),
                                     Eigen::Vector3d(1.0, 1.0, 0.5)};
  int splits = 0;
  for (int round = 0; round < 3; ++round)
    for (int p = 0; p < incremental.node_count && splits < 60; p += 7) {
      const Eigen::Vector3d& normal = normals[static_cast<std::size_t>((p + round) % 4)];
      const int copy = split_by_hand(incremental, p, normal);
      if (copy < 0) continue;
      ASSERT_EQ(split_by_hand(full, p, normal), copy);
      merge_springs_after_split(incremental, p, copy);
      merge_springs(full);
      expect_equal_springs(incremental, full, "split " + std::to_string(splits) + " of node " + std::to_string(p));
      ++splits;
    }
  EXPECT_GE(splits, 30);
  // Keys that are not among the kept ones (here: the split named with a wrong original): the
  // whole network is merged again, with the same result.
  int copy = -1, p = 0;
  for (; p < incremental.node_count && copy < 0; ++p) copy = split_by_hand(incremental, p, normals[0]);
  ASSERT_GE(copy, 0);
  ASSERT_EQ(split_by_hand(full, p - 1, normals[0]), copy);
  merge_springs_after_split(incremental, copy - 1, copy);
  merge_springs(full);
  expect_equal_springs(incremental, full, "a split named with a wrong original");
}

} // namespace
} // namespace kerf
