// Paper 000 §3.2 geometric cutting. Expected values: the volumes of a cube on either side of a
// plane, in closed form; the conservation of volume; a closed, consistently oriented boundary per
// fragment (every directed boundary edge meets its reverse); the locally updated adjacency equal
// to the one recomputed from scratch (meshes/tet_mesh.hpp's tet_face_adjacency).

#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/geometric_cut.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

using namespace kerf;

namespace {

// The unit cube in 10 x 10 x 10 cells of 6 tetrahedra: 6000 tetrahedra (paper 000 §3.2's size).
// box_tet_mesh at this commit stores the Kuhn tetrahedra of the permutations with two inversions
// negatively oriented (its parity test sums into a bool), so they are re-oriented here; the cut
// itself refuses inverted input.
TetMesh cube() {
  TetMesh m = box_tet_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 10, 10, 10);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    auto p = [&](int k) { return Eigen::Vector3d(m.nodes.row(m.tets(t, k))); };
    if (signed_volume(p(0), p(1), p(2), p(3)) < 0.0) std::swap(m.tets(t, 2), m.tets(t, 3));
  }
  return m;
}

/// An edge of length 4 along unit `a` swept along unit `b` from -2 to +2 through `origin` in 10
/// positions: 18 triangles covering the plane through `origin` spanned by a and b inside the cube.
SweptSurface plane_sweep(const Eigen::Vector3d& origin, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         double from = -2.0, double to = 2.0) {
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 10; ++k) centres.push_back(origin + (from + (to - from) * k / 9.0) * b);
  return sweep_edge(centres, a, 4.0);
}

void expect_sound(const CuttableBody& body, double volume) {
  const TetMesh& m = body.mesh();
  double total = 0.0;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    auto p = [&](int k) { return Eigen::Vector3d(m.nodes.row(m.tets(t, k))); };
    const double v = signed_volume(p(0), p(1), p(2), p(3));
    ASSERT_GT(v, 0.0) << "tetrahedron " << t << " inverted or flat";
    total += v;
  }
  EXPECT_NEAR(total, volume, 1e-12 * volume);
  // The local adjacency update equals the global recomputation.
  EXPECT_TRUE(body.adjacency() == tet_face_adjacency(m.tets));
  // Each fragment's boundary is closed and consistently oriented.
  for (int f = 0; f < body.fragment_count(); ++f) {
    std::vector<int> rows;
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      if (body.fragment_of_tet()[static_cast<std::size_t>(t)] == f) rows.push_back(static_cast<int>(t));
    Eigen::MatrixXi tets(static_cast<Eigen::Index>(rows.size()), 4);
    for (std::size_t i = 0; i < rows.size(); ++i) tets.row(static_cast<Eigen::Index>(i)) = m.tets.row(rows[i]);
    const Eigen::MatrixXi faces = boundary_faces(tets);
    std::map<std::pair<int, int>, int> half_edges;
    for (Eigen::Index i = 0; i < faces.rows(); ++i)
      for (int k = 0; k < 3; ++k) ++half_edges[{faces(i, k), faces(i, (k + 1) % 3)}];
    for (const auto& [e, count] : half_edges) {
      const auto reverse = half_edges.find({e.second, e.first});
      ASSERT_TRUE(reverse != half_edges.end() && reverse->second == count)
          << "fragment " << f << ": boundary edge " << e.first << "-" << e.second << " is open";
    }
  }
}

} // namespace

TEST(GeometricCut, TiltedPlaneThroughA6000TetCubeGivesTheAnalyticVolumes) {
  // Plane x + 0.3 y + 0.2 z = 0.6 crosses every x-line of the unit cube (0.1 <= x <= 0.6), so
  // the side x < ... has volume ∫∫ (0.6 - 0.3 y - 0.2 z) dy dz = 0.6 - 0.15 - 0.1 = 0.35.
  CuttableBody body(cube());
  ASSERT_EQ(body.mesh().tets.rows(), 6000);
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
  const Eigen::Vector3d origin = 0.6 / Eigen::Vector3d(1.0, 0.3, 0.2).norm() * normal;
  const Eigen::Vector3d a = normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d b = normal.cross(a);
  const SweptSurface surface = plane_sweep(origin, a, b);
  ASSERT_EQ(surface.triangles.rows(), 18);
  const GeometricCutReport report = body.cut(surface);
  EXPECT_EQ(report.fragments, 2);
  EXPECT_GT(report.cut_tets, 0);
  EXPECT_GT(report.min_volume_ratio, 0.0);
  std::vector<double> v = body.fragment_volumes();
  std::sort(v.begin(), v.end());
  EXPECT_NEAR(v[0], 0.35, 1e-12 * 0.35);
  EXPECT_NEAR(v[1], 0.65, 1e-12 * 0.65);
  expect_sound(body, 1.0);
}

TEST(GeometricCut, PlanesThroughNodesAndAlongEdgesSplitCleanly) {
  // x = 0.5 is a grid plane (through nodes, along edges and faces); x = y holds the diagonals of
  // the Kuhn tetrahedra. Each halves the cube.
  struct Case { Eigen::Vector3d origin, a, b; };
  const Eigen::Vector3d d = Eigen::Vector3d(1.0, 1.0, 0.0).normalized();
  for (const Case& c : {Case{{0.5, 0.5, 0.5}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
                        Case{{0.5, 0.5, 0.5}, d, Eigen::Vector3d::UnitZ()}}) {
    CuttableBody body(cube());
    const GeometricCutReport report = body.cut(plane_sweep(c.origin, c.a, c.b));
    EXPECT_EQ(report.fragments, 2);
    EXPECT_GT(report.snapped_nodes, 0);
    std::vector<double> v = body.fragment_volumes();
    ASSERT_EQ(v.size(), 2u);
    EXPECT_NEAR(v[0], 0.5, 1e-12);
    EXPECT_NEAR(v[1], 0.5, 1e-12);
    expect_sound(body, 1.0);
  }
}

TEST(GeometricCut, NearDegenerateOffsetsNeitherInvertNorLoseVolume) {
  // The grid plane x = 0.5 moved by 1e-15 ... 1e-2 of a cell: below the snap tolerance the nodes
  // go on the surface, above it thin but positive parts are made; volume is conserved always.
  for (double offset : {1e-15, 1e-11, 1e-7, 1e-5, 1e-4, 1e-3, 1e-2}) {
    CuttableBody body(cube());
    const GeometricCutReport report =
        body.cut(plane_sweep({0.5 + offset * 0.1, 0.5, 0.5}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()));
    EXPECT_EQ(report.fragments, 2) << offset;
    EXPECT_GT(report.min_volume_ratio, 1e-14) << offset;
    expect_sound(body, 1.0);
    // Snapping moves the cut by at most the tolerance (1e-4 of the mean edge length).
    std::vector<double> v = body.fragment_volumes();
    std::sort(v.begin(), v.end());
    EXPECT_NEAR(v[0], 0.5 - offset * 0.1, 2e-5) << offset;
  }
}

/// Area of the boundary faces of the body that lie in the plane x = x0 (within 1e-12), both
/// sides counted.
double boundary_area_in_plane_x(const CuttableBody& body, double x0) {
  const TetMesh& m = body.mesh();
  const Eigen::MatrixXi faces = boundary_faces(m.tets);
  double area = 0.0;
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    const Eigen::Vector3d a = m.nodes.row(faces(i, 0)), b = m.nodes.row(faces(i, 1)), c = m.nodes.row(faces(i, 2));
    if (std::abs(a.x() - x0) < 1e-12 && std::abs(b.x() - x0) < 1e-12 && std::abs(c.x() - x0) < 1e-12)
      area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

TEST(GeometricCut, ACutThatStopsInsideOpensASlitBehindItsFront) {
  // The edge (along y, longer than the cube) sweeps the plane x = 0.55 from above the cube down to
  // z = 0.4 only: a slit of 1 x 0.6 in the cube. Progressive splitting: the crossed tetrahedra
  // are divided, the crack opens behind the front and stays closed at it, so the body is one
  // fragment whose boundary gains both faces of the slit: 2 x 0.6 in the plane x = 0.55, up to
  // the front's resolution (the front is resolved to within one cell, 0.1, of z = 0.4:
  // 2 x 0.5 <= area <= 2 x 0.7). Expected values: the geometry of the slit.
  CuttableBody body(cube());
  const GeometricCutReport report =
      body.cut(plane_sweep({0.55, 0.5, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -0.6, 1.0));
  EXPECT_EQ(report.fragments, 1);
  EXPECT_GT(report.cut_tets, 0);
  EXPECT_GT(report.min_volume_ratio, 0.0);
  expect_sound(body, 1.0);
  const double slit = boundary_area_in_plane_x(body, 0.55);
  EXPECT_GE(slit, 2.0 * 0.5);
  EXPECT_LE(slit, 2.0 * 0.7);
  // No node below the front was opened: every boundary face in the plane lies at z >= 0.3.
  const Eigen::MatrixXi faces = boundary_faces(body.mesh().tets);
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    bool in_plane = true;
    double z = 1.0;
    for (int k = 0; k < 3; ++k) {
      in_plane = in_plane && std::abs(body.mesh().nodes(faces(i, k), 0) - 0.55) < 1e-12;
      z = std::min(z, body.mesh().nodes(faces(i, k), 2));
    }
    if (in_plane) {
      EXPECT_GE(z, 0.3 - 1e-12);
    }
  }
}

TEST(GeometricCut, ACutContinuedThroughTheBodySeparatesItWithTheAnalyticVolumes) {
  // The slit above, then the edge's sweep continued from z = 0.4 to below the cube: the second
  // cut meets the first one's front and separates the cube at x = 0.55: volumes 0.55 and 0.45.
  CuttableBody body(cube());
  body.cut(plane_sweep({0.55, 0.5, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -0.6, 1.0));
  const GeometricCutReport second =
      body.cut(plane_sweep({0.55, 0.5, 0.4}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -0.6, 0.0));
  EXPECT_EQ(second.fragments, 2);
  std::vector<double> v = body.fragment_volumes();
  std::sort(v.begin(), v.end());
  EXPECT_NEAR(v[0], 0.45, 1e-12);
  EXPECT_NEAR(v[1], 0.55, 1e-12);
  expect_sound(body, 1.0);
}

TEST(GeometricCut, ATiltedCutThatStopsInsideKeepsVolumeAndOrientation) {
  // The tilted plane of the first test, swept only half way (its strip ends inside the cube):
  // every part positive, volume conserved to 1e-12, one fragment with a closed boundary.
  CuttableBody body(cube());
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
  const Eigen::Vector3d origin = 0.6 / Eigen::Vector3d(1.0, 0.3, 0.2).norm() * normal;
  const Eigen::Vector3d a = normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d b = normal.cross(a);
  const GeometricCutReport report = body.cut(plane_sweep(origin, a, b, -2.0, 0.05));
  EXPECT_EQ(report.fragments, 1);
  EXPECT_GT(report.cut_tets, 0);
  EXPECT_GT(report.min_volume_ratio, 0.0);
  expect_sound(body, 1.0);
}

TEST(GeometricCut, TwoCutsMakeFourQuarters) {
  CuttableBody body(cube());
  body.cut(plane_sweep({0.45, 0.5, 0.5}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()));
  const GeometricCutReport second = body.cut(plane_sweep({0.5, 0.63, 0.5}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(second.fragments, 4);
  std::vector<double> v = body.fragment_volumes();
  std::sort(v.begin(), v.end());
  // Quarters of the unit cube: 0.45 x 0.63, 0.45 x 0.37, 0.55 x 0.63, 0.55 x 0.37.
  const std::vector<double> expected{0.45 * 0.37, 0.55 * 0.37, 0.45 * 0.63, 0.55 * 0.63};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(v[i], expected[i], 1e-12) << i;
  expect_sound(body, 1.0);
}

TEST(SweptSurface, StripOfTriangles) {
  const std::vector<Eigen::Vector3d> centres{{0, 0, 1}, {0, 0, 0}, {0, 0, -1}};
  const SweptSurface s = sweep_edge(centres, Eigen::Vector3d::UnitY(), 2.0);
  EXPECT_EQ(s.triangles.rows(), 4);
  EXPECT_EQ(s.vertices.rows(), 6);
  EXPECT_TRUE(s.vertices.row(1).isApprox(Eigen::RowVector3d(0, 1, 1)));
  EXPECT_THROW(sweep_edge(std::vector<Eigen::Vector3d>{{0, 0, 0}}, Eigen::Vector3d::UnitY(), 1.0), std::invalid_argument);
}
