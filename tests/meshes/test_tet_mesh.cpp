// Tests of meshes/tet_mesh on hand-built meshes whose volumes, areas and faces are known.
#include "meshes/tet_mesh.hpp"

#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <map>
#include <set>

namespace kerf {
namespace {

/// Unit cube split into the 6 Kuhn tetrahedra around its diagonal (0,0,0)-(1,1,1); corner
/// (x, y, z) has index x + 2y + 4z. Each tetrahedron is stored positively oriented.
TetMesh kuhn_cube() {
  TetMesh mesh;
  mesh.nodes.resize(8, 3);
  for (int i = 0; i < 8; ++i) mesh.nodes.row(i) << (i & 1), ((i >> 1) & 1), ((i >> 2) & 1);
  const std::array<std::array<int, 3>, 6> axis_orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  mesh.tets.resize(6, 4);
  for (int t = 0; t < 6; ++t) {
    int corner = 0;
    mesh.tets(t, 0) = corner;
    for (int k = 0; k < 3; ++k) {
      corner |= 1 << axis_orders[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)];
      mesh.tets(t, k + 1) = corner;
    }
    if (signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                      mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose()) < 0)
      std::swap(mesh.tets(t, 2), mesh.tets(t, 3));
  }
  // `first_x`: the two tetrahedra whose path from the origin starts along x.
  mesh.volume_groups.push_back({"body", 1, {0, 1, 2, 3, 4, 5}});
  mesh.volume_groups.push_back({"first_x", 2, {0, 1}});
  SurfaceGroup bottom{"bottom", 3, Eigen::MatrixXi(2, 3)};
  bottom.triangles << 0, 3, 1, 0, 2, 3; // z = 0, two triangles
  mesh.surface_groups.push_back(bottom);
  return mesh;
}

TEST(TetMesh, KuhnCubeVolumeAndOrientation) {
  const TetMesh mesh = kuhn_cube();
  // Analytic: the six Kuhn tetrahedra each have volume 1/6 and fill the unit cube.
  EXPECT_NEAR(mesh_volume(mesh), 1.0, 1e-15);
  for (int t = 0; t < 6; ++t)
    EXPECT_NEAR(signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                              mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose()),
                1.0 / 6.0, 1e-15);
}

TEST(TetMesh, BoundaryFacesOfKuhnCube) {
  const TetMesh mesh = kuhn_cube();
  const Eigen::MatrixXi faces = boundary_faces(mesh.tets);
  // Each of the 6 square faces of the cube is split into 2 triangles.
  ASSERT_EQ(faces.rows(), 12);
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  double area = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d a = mesh.nodes.row(faces(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(faces(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(faces(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    // Outward: the normal points away from the cube's centre (convex body).
    EXPECT_GT(n.dot((a + b + c) / 3.0 - centre), 0.0);
    area += 0.5 * n.norm();
  }
  EXPECT_NEAR(area, 6.0, 1e-14); // analytic: 6 unit squares
}

TEST(TetMesh, FaceAdjacencyIsSymmetricAndSharesFaces) {
  const TetMesh mesh = kuhn_cube();
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  ASSERT_EQ(adjacency.rows(), 6);
  int interior = 0;
  for (int t = 0; t < 6; ++t)
    for (int k = 0; k < 4; ++k) {
      const int u = adjacency(t, k);
      if (u < 0) continue;
      ++interior;
      // Symmetric: u lists t across some face, and that face has the same three nodes.
      std::set<int> face_t;
      for (int j = 0; j < 4; ++j)
        if (j != k) face_t.insert(mesh.tets(t, j));
      int back = -1;
      for (int j = 0; j < 4; ++j)
        if (adjacency(u, j) == t) back = j;
      ASSERT_GE(back, 0);
      std::set<int> face_u;
      for (int j = 0; j < 4; ++j)
        if (j != back) face_u.insert(mesh.tets(u, j));
      EXPECT_EQ(face_t, face_u);
    }
  // 24 tet faces = 12 boundary + 2 x 6 interior faces (Euler count for the Kuhn cube).
  EXPECT_EQ(interior, 12);
}

TEST(TetMesh, NonManifoldFaceIsAnError) {
  Eigen::MatrixXi tets(3, 4);
  tets << 0, 1, 2, 3, 0, 1, 2, 4, 0, 1, 2, 5;
  EXPECT_THROW((void)tet_face_adjacency(tets), MeshError);
}

TEST(TetMesh, GroupsVolumesAreasRegions) {
  const TetMesh mesh = kuhn_cube();
  ASSERT_NE(mesh.find_volume_group("body"), nullptr);
  EXPECT_EQ(mesh.find_volume_group("nope"), nullptr);
  ASSERT_NE(mesh.find_surface_group("bottom"), nullptr);
  EXPECT_EQ(mesh.find_surface_group("body"), nullptr);
  EXPECT_NEAR(group_volume(mesh, "body"), 1.0, 1e-15);
  EXPECT_NEAR(group_volume(mesh, "first_x"), 2.0 / 6.0, 1e-15); // two Kuhn tets of 1/6
  EXPECT_NEAR(surface_group_area(mesh, "bottom"), 1.0, 1e-15);  // the unit square z = 0
  EXPECT_THROW((void)group_volume(mesh, "missing"), MeshError);
  EXPECT_THROW((void)surface_group_area(mesh, "missing"), MeshError);

  // First listed group wins; tets in none of the listed groups get -1.
  const Eigen::VectorXi regions = tet_regions(mesh, {"first_x", "body"});
  EXPECT_EQ(regions(0), 0);
  EXPECT_EQ(regions(1), 0);
  for (int t = 2; t < 6; ++t) EXPECT_EQ(regions(t), 1);
  const Eigen::VectorXi only = tet_regions(mesh, {"first_x"});
  EXPECT_EQ(only(0), 0);
  EXPECT_EQ(only(5), -1);
  EXPECT_THROW((void)tet_regions(mesh, {"missing"}), MeshError);
}

TEST(TetMesh, EmptyMesh) {
  const TetMesh mesh;
  EXPECT_EQ(mesh_volume(mesh), 0.0);
  EXPECT_EQ(boundary_faces(mesh.tets).rows(), 0);
  EXPECT_EQ(tet_face_adjacency(mesh.tets).rows(), 0);
}

} // namespace
} // namespace kerf
