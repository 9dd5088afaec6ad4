// The local voxel grid: surface points cast from the polygon, occupancy, re-centring that keeps
// the overlap, lowering that moves the polygon's vertices, and memory fixed by the cell counts.

#include "realtime/voxel/local_voxel_grid.hpp"
#include "tests/realtime/voxel/voxel_test_setup.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

namespace {

struct Body {
  SurfaceMesh surface;
  AabbTree tree;
};

Body cube(double edge, int cells) {
  Body b;
  b.surface = test::cube_surface(edge, cells);
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(b.surface.triangles.rows()));
  for (Eigen::Index f = 0; f < b.surface.triangles.rows(); ++f)
    for (int c = 0; c < 3; ++c) boxes[static_cast<std::size_t>(f)].extend(b.surface.vertices.row(b.surface.triangles(f, c)).transpose());
  b.tree = AabbTree(boxes);
  return b;
}

VoxelFrame top_frame(double x, double y, double top) {
  VoxelFrame f;
  f.origin = {x, y, top};
  f.depth_axis = -Eigen::Vector3d::UnitZ();
  f.u_axis = Eigen::Vector3d::UnitX();
  f.v_axis = f.depth_axis.cross(f.u_axis);
  return f;
}

} // namespace

TEST(LocalVoxelGrid, SurfacePointsOfAFlatTopAreItsPlaneAndNoneBeyondTheEdge) {
  const Body body = cube(1e-3, 10);
  const double h = 2e-5;
  LocalVoxelGrid grid({10, 20, 20}, h, 4096);
  // Origin on the top face 0.1 mm from the x = 0 edge: columns with a < -0.1 mm are off the body.
  ASSERT_TRUE(grid.place(top_frame(1e-4, 0.0, 1e-3), -10, -10, -5, body.surface.vertices, body.surface.triangles,
                         body.tree, 0.0, false));
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      const double a_centre = grid.a_lower(i) + 0.5 * h;
      if (a_centre < -1e-4) {
        EXPECT_EQ(grid.surface_depth(i, j), LocalVoxelGrid::no_material) << i << "," << j;
      } else {
        EXPECT_NEAR(grid.surface_depth(i, j), 0.0, 1e-15) << i << "," << j; // the top face z = 1 mm
        // Layers -5..4: cells below depth 0 are material, those above are not.
        for (int k = 0; k < 10; ++k) EXPECT_EQ(grid.occupied(i, j, k), k >= 5);
      }
    }
}

TEST(LocalVoxelGrid, LoweringMovesTheSurfacePointAndThePolygonAndSurvivesReplacement) {
  Body body = cube(1e-3, 50); // vertices every 0.02 mm: one per column corner
  const Eigen::MatrixXd original = body.surface.vertices;
  const double h = 2e-5;
  LocalVoxelGrid grid({10, 20, 20}, h, 8192);
  const VoxelFrame frame = top_frame(0.5e-3 + 0.5 * h, 0.5 * h, 1e-3); // a vertex inside column (10, 10)
  grid.place(frame, -10, -10, -5, body.surface.vertices, body.surface.triangles, body.tree, 0.0, false);
  const double moved = grid.lower(10, 10, 3 * h, body.surface.vertices, original);
  EXPECT_DOUBLE_EQ(grid.surface_depth(10, 10), 3 * h);
  EXPECT_NEAR(moved, 3 * h, 1e-15); // the vertex at the column's lower corner went down 3 h
  // Re-placing two columns over keeps the lowered column where it now is (index 8).
  grid.place(frame, -8, -10, -5, body.surface.vertices, body.surface.triangles, body.tree, moved, true);
  EXPECT_DOUBLE_EQ(grid.surface_depth(8, 10), 3 * h);
  EXPECT_NEAR(grid.surface_depth(0, 0), 0.0, 1e-15);
  // A fresh grid (no overlap kept) finds the cut from the moved polygon: the column whose
  // centre line meets the triangles around the moved vertex sees them lowered.
  LocalVoxelGrid fresh({10, 20, 20}, h, 8192);
  fresh.place(frame, -10, -10, -5, body.surface.vertices, body.surface.triangles, body.tree, moved, false);
  EXPECT_GT(fresh.surface_depth(10, 10), 0.5 * h);
}

TEST(LocalVoxelGrid, MemoryIsFixedByTheCellCountsNotTheBody) {
  const Body small = cube(1e-3, 10), large = cube(0.1, 30);
  LocalVoxelGrid a({10, 20, 20}, 2e-5, 4096), b({10, 20, 20}, 2e-5, 4096);
  const std::size_t before = a.memory_bytes();
  a.place(top_frame(5e-4, 0.0, 1e-3), -10, -10, -5, small.surface.vertices, small.surface.triangles, small.tree, 0.0, false);
  b.place(top_frame(5e-2, 0.0, 0.1), -10, -10, -5, large.surface.vertices, large.surface.triangles, large.tree, 0.0, false);
  EXPECT_EQ(a.memory_bytes(), before);
  EXPECT_EQ(a.memory_bytes(), b.memory_bytes());
  // 400 columns x 3 doubles + 400 flags + 4096 x 4 ints: about 79 kB, against 1 GB for the
  // 500^3 bytes of a whole-body voxel model (paper 002 §4).
  EXPECT_LT(a.memory_bytes(), 100000u);
}

TEST(LocalVoxelGrid, RejectsBadSizes) {
  EXPECT_THROW(LocalVoxelGrid({0, 20, 20}, 2e-5, 10), std::invalid_argument);
  EXPECT_THROW(LocalVoxelGrid({10, 20, 20}, 0.0, 10), std::invalid_argument);
  EXPECT_THROW(LocalVoxelGrid({10, 20, 20}, 2e-5, 0), std::invalid_argument);
}
