// box_tet_mesh against the box it meshes: every tetrahedron positive with volume V_box / (6 n),
// the total equal to the box volume, the boundary closed and equal to the named faces, and the
// Kuhn subdivision conforming (each interior face shared by exactly two tetrahedra).

#include "meshes/box_tet_mesh.hpp"
#include "meshes/surface_mesh.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

using namespace kerf;

TEST(BoxTetMesh, EveryTetrahedronIsPositiveAndTheVolumeIsTheBox) {
  const Eigen::Vector3d lower(0.0, -0.010, 0.0), upper(0.040, 0.010, 0.015);
  for (const auto& n : {std::array<int, 3>{1, 1, 1}, std::array<int, 3>{3, 2, 4}, std::array<int, 3>{10, 10, 10}}) {
    const TetMesh mesh = box_tet_mesh(lower, upper, n[0], n[1], n[2]);
    const double box = (upper - lower).prod();
    const double each = box / (6.0 * n[0] * n[1] * n[2]); // the 6 Kuhn tetrahedra of a cell are equal
    ASSERT_EQ(mesh.tets.rows(), 6 * n[0] * n[1] * n[2]);
    for (int t = 0; t < mesh.tets.rows(); ++t) {
      const double v = signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                                     mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose());
      ASSERT_NEAR(v, each, 1e-12 * each) << "tetrahedron " << t;
    }
    EXPECT_NEAR(mesh_volume(mesh), box, 1e-12 * box);
    EXPECT_EQ(tet_quality_summary(mesh).inverted, 0);
  }
}

TEST(BoxTetMesh, BoundaryIsClosedAndCoveredByTheNamedFaces) {
  const TetMesh mesh = box_tet_mesh({0, 0, 0}, {1, 2, 3}, 3, 2, 4);
  // Divergence theorem on the boundary of the tetrahedra gives the box volume 6.
  EXPECT_NEAR(enclosed_volume(boundary_surface(mesh)), 6.0, 1e-12);
  // 2 triangles per boundary quad: 2 (3*2 + 3*4 + 2*4) * 2 sides = 104 = the boundary faces.
  long named = 0;
  for (const SurfaceGroup& g : mesh.surface_groups) named += g.triangles.rows();
  EXPECT_EQ(named, boundary_faces(mesh.tets).rows());
  EXPECT_EQ(named, 104);
  // Conformity: every face is either a boundary face or shared by exactly two tetrahedra.
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  long interior = 0;
  for (int t = 0; t < adjacency.rows(); ++t)
    for (int k = 0; k < 4; ++k) interior += adjacency(t, k) >= 0;
  EXPECT_EQ(interior + named, 4 * mesh.tets.rows());
}

TEST(BoxTetMesh, SurfaceQueryClassifiesPointsOfTheBox) {
  // Point-in-volume on the boundary of a box mesh against the box itself (closed form): every
  // point of a 16^3 lattice strictly inside is inside, every point of a shell around it outside.
  const Eigen::Vector3d lower(0.0, 0.0, 0.0), upper(0.040, 0.040, 0.020);
  const SurfaceQuery query(boundary_surface(box_tet_mesh(lower, upper, 8, 8, 4)));
  int inside = 0, outside = 0;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j)
      for (int k = 0; k < 16; ++k) {
        const Eigen::Vector3d s((i + 0.5) / 16.0, (j + 0.5) / 16.0, (k + 0.5) / 16.0);
        const Eigen::Vector3d p = lower.array() + s.array() * (upper - lower).array();
        inside += query.contains(p);
        const Eigen::Vector3d q = lower.array() + (1.2 * s.array() - 0.1) * (upper - lower).array();
        const bool strictly_out = ((q - lower).array() < 0.0).any() || ((q - upper).array() > 0.0).any();
        if (strictly_out) outside += !query.contains(q);
        else outside += 1; // inside the box: counted by the first lattice
      }
  EXPECT_EQ(inside, 16 * 16 * 16);
  EXPECT_EQ(outside, 16 * 16 * 16);
}
