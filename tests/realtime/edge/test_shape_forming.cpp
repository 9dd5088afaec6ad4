// Paper 000 §4: cutting and deforming on one fine TetMesh. A blade cuts a clay block in two with
// the edge model (its geometric cut on the worker thread), then a stylus pulls the piece it
// touches with the spring network built on that piece's tetrahedra. Expected values, each
// independent of the code under test: the pieces' volumes and base areas in closed form; the
// other piece is not part of the network, so its nodes keep their positions bit for bit; the
// body resists the pull (force against the pull, finite at every sample).

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/shape_forming_model.hpp"
#include "tests/realtime/edge/shape_forming_fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

using namespace kerf;


TEST(ShapeForming, CutInTwoThenPullOnePiece) {
  // 40 x 40 x 20 mm in 2.5 mm cells; the blade cuts at x = 16 mm (not a grid plane).
  const TetMesh mesh = box_tet_mesh({0.0, -0.020, 0.0}, {0.040, 0.020, 0.020}, 16, 16, 8);
  ShapeFormingModel model(mesh, test::clay_setup());
  ASSERT_EQ(model.tool_count(), 2);

  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> forces;
  tools[1].position = {0.008, 0.0, 0.022};
  // The cut: from 1 mm above the top to 1 mm below the base at 10 mm/s, 1 kHz.
  for (int k = 0; k <= 2200; ++k) {
    tools[0].position = {0.016, 0.0, 0.021 - 1e-5 * k};
    tools[0].velocity = {0.0, 0.0, -0.01};
    model.step(tools, 1e-3, forces);
    ASSERT_TRUE(forces[0].force.allFinite());
  }
  tools[0].velocity.setZero();
  // The stylus waits at its start until the stage is published.
  long waited = 0;
  while (!model.active_stage() && waited < 100'000'000) {
    model.step(tools, 1e-3, forces);
    ++waited;
    if (!model.active_stage()) {
      EXPECT_EQ(forces[1].mode, InteractionMode::no_contact);
    }
  }
  ASSERT_NE(model.active_stage(), nullptr) << model.edge().geometric_cut()->error();
  const CuttableBody& body = model.edge().geometric_cut()->body();
  ASSERT_EQ(body.fragment_count(), 2);
  // Volumes: 16 x 40 x 20 mm^3 and 24 x 40 x 20 mm^3.
  std::vector<double> v = body.fragment_volumes();
  std::sort(v.begin(), v.end());
  EXPECT_NEAR(v[0], 0.016 * 0.040 * 0.020, 1e-12 * 0.016 * 0.040 * 0.020);
  EXPECT_NEAR(v[1], 0.024 * 0.040 * 0.020, 1e-12 * 0.024 * 0.040 * 0.020);

  // The stage is the 16 mm piece, its support the 16 x 40 mm part of the base.
  const FormingStage& stage = *model.active_stage();
  EXPECT_NEAR(std::abs(mesh_volume(stage.mesh)), 0.016 * 0.040 * 0.020, 1e-12 * 0.016 * 0.040 * 0.020);
  const SurfaceGroup* support = stage.mesh.find_surface_group("support");
  ASSERT_NE(support, nullptr);
  double area = 0.0;
  for (Eigen::Index f = 0; f < support->triangles.rows(); ++f) {
    const Eigen::Vector3d a = stage.mesh.nodes.row(support->triangles(f, 0)), b = stage.mesh.nodes.row(support->triangles(f, 1)),
                          c = stage.mesh.nodes.row(support->triangles(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  EXPECT_NEAR(area, 0.016 * 0.040, 1e-12);
  // The stage carries the body as this cut left it (what the viewer draws): the body's own mesh
  // and fragment labels, the stage's fragment among them on exactly the stage's tetrahedra.
  EXPECT_EQ(stage.cut_mesh.nodes, body.mesh().nodes);
  EXPECT_EQ(stage.cut_mesh.tets, body.mesh().tets);
  EXPECT_EQ(stage.fragment_of_tet, body.fragment_of_tet());
  EXPECT_EQ(std::count(stage.fragment_of_tet.begin(), stage.fragment_of_tet.end(), stage.fragment), stage.mesh.tets.rows());

  // The pull: 5 mm up at 10 mm/s, then a hold.
  const Eigen::MatrixXd cut_nodes = body.mesh().nodes;
  for (int k = 1; k <= 600; ++k) {
    tools[1].position = {0.008, 0.0, 0.022 + 1e-5 * std::min(k, 500)};
    tools[1].velocity = {0.0, 0.0, k <= 500 ? 0.01 : 0.0};
    model.step(tools, 1e-3, forces);
    ASSERT_TRUE(forces[1].force.allFinite()) << k;
    EXPECT_FALSE(forces[1].over_budget) << k;
  }
  // The body pulls the stylus back: the force on it is against the pull (+z), finite.
  EXPECT_LT(forces[1].force.z(), 0.0);
  EXPECT_GT(-forces[1].force.z(), 1e-3);

  const TetMesh formed = model.formed_mesh();
  ASSERT_EQ(formed.nodes.rows(), cut_nodes.rows());
  std::vector<char> in_stage(static_cast<std::size_t>(cut_nodes.rows()), 0);
  for (int g : stage.cut_mesh_node) in_stage[static_cast<std::size_t>(g)] = 1;
  double moved = 0.0;
  long other = 0;
  for (Eigen::Index g = 0; g < cut_nodes.rows(); ++g) {
    const double d = (formed.nodes.row(g) - cut_nodes.row(g)).norm();
    if (in_stage[static_cast<std::size_t>(g)]) {
      moved = std::max(moved, d);
    } else {
      ++other;
      EXPECT_EQ(d, 0.0) << "node " << g << " of the other piece moved";
    }
  }
  EXPECT_GT(other, 0);
  // The top of the pulled piece follows the stylus (5 mm) by at least half.
  EXPECT_GT(moved, 2.5e-3);
  EXPECT_LT(moved, 5.5e-3);
}
