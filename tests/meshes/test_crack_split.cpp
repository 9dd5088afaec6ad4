// Splitting a mesh along an internal surface (meshes/crack_split.hpp). Expected values come from
// the structured box mesh's own counts (nodes on a grid plane, faces per cell face) and from
// geometry (the volumes on either side of a plane), not from the code under test.

#include "meshes/box_tet_mesh.hpp"
#include "meshes/crack_split.hpp"
#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace kerf {
namespace {

/// The interior faces of `mesh` whose three nodes lie on the plane x = x0 and satisfy `keep`,
/// added as the surface group `cut_plane` (the conformingly meshed internal surface of a scene).
template <class Keep>
void add_plane_group(TetMesh& mesh, double x0, Keep keep) {
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  constexpr int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::vector<Eigen::RowVector3i> rows;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int u = adjacency(t, k);
      if (u < t) continue; // boundary (−1) or seen from the other side already
      Eigen::RowVector3i tri(mesh.tets(t, faces[k][0]), mesh.tets(t, faces[k][1]), mesh.tets(t, faces[k][2]));
      bool on_plane = true;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int j = 0; j < 3; ++j) {
        on_plane = on_plane && std::abs(mesh.nodes(tri(j), 0) - x0) < 1e-12;
        centroid += mesh.nodes.row(tri(j)).transpose() / 3.0;
      }
      if (on_plane && keep(centroid)) rows.push_back(tri);
    }
  SurfaceGroup group{"cut_plane", 99, Eigen::MatrixXi(static_cast<Eigen::Index>(rows.size()), 3)};
  for (std::size_t i = 0; i < rows.size(); ++i) group.triangles.row(static_cast<Eigen::Index>(i)) = rows[i];
  mesh.surface_groups.push_back(group);
}

double component_volume(const TetMesh& mesh, const Eigen::VectorXi& component, int c) {
  double v = 0.0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (component(t) == c)
      v += signed_volume(mesh.nodes.row(mesh.tets(t, 0)), mesh.nodes.row(mesh.tets(t, 1)), mesh.nodes.row(mesh.tets(t, 2)),
                             mesh.nodes.row(mesh.tets(t, 3)));
  return v;
}

TEST(CrackSplit, ThroughCutGivesTwoBodiesWithThePlaneVolumes) {
  // Box 4 x 3 x 3 (units arbitrary) with 4 x 3 x 3 cells: the plane x = 2 holds 4 x 4 = 16 grid
  // nodes and 3 x 3 cell faces of 2 triangles each = 18 triangles.
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 3, 3), 4, 3, 3);
  add_plane_group(mesh, 2.0, [](const Eigen::Vector3d&) { return true; });
  ASSERT_EQ(mesh.find_surface_group("cut_plane")->triangles.rows(), 18);

  const CrackSplit split = split_along_surface(mesh, "cut_plane");
  EXPECT_EQ(split.mesh.nodes.rows(), mesh.nodes.rows() + 16);
  EXPECT_EQ(split.original_node.size(), static_cast<std::size_t>(split.mesh.nodes.rows()));

  const Eigen::VectorXi component = face_connected_components(split.mesh.tets);
  ASSERT_EQ(component.maxCoeff(), 1) << "a through cut leaves two bodies";
  // Each side of x = 2 is a 2 x 3 x 3 box: volume 18 (exact in binary floating point up to the
  // rounding of the tetrahedron sum).
  EXPECT_NEAR(component_volume(split.mesh, component, 0), 18.0, 1e-12);
  EXPECT_NEAR(component_volume(split.mesh, component, 1), 18.0, 1e-12);

  // The crack faces are now boundary faces: 2 x 18 more than before, and the pairs coincide.
  EXPECT_EQ(boundary_faces(split.mesh.tets).rows(), boundary_faces(mesh.tets).rows() + 36);
  for (Eigen::Index f = 0; f < split.plus_faces.rows(); ++f)
    for (int j = 0; j < 3; ++j) {
      EXPECT_NE(split.plus_faces(f, j), split.minus_faces(f, j));
      EXPECT_EQ(split.mesh.nodes.row(split.plus_faces(f, j)), split.mesh.nodes.row(split.minus_faces(f, j)));
      EXPECT_EQ(split.original_node[static_cast<std::size_t>(split.plus_faces(f, j))],
                split.original_node[static_cast<std::size_t>(split.minus_faces(f, j))]);
    }
  // The + side is the side the triangle normal points into: every tetrahedron using a + node lies
  // on that side (centroid x compared with the plane, by the normal's sign).
  for (Eigen::Index f = 0; f < split.plus_faces.rows(); ++f) {
    const Eigen::Vector3d a = split.mesh.nodes.row(split.plus_faces(f, 0));
    const Eigen::Vector3d n = (Eigen::Vector3d(split.mesh.nodes.row(split.plus_faces(f, 1))) - a)
                                  .cross(Eigen::Vector3d(split.mesh.nodes.row(split.plus_faces(f, 2))) - a);
    for (Eigen::Index t = 0; t < split.mesh.tets.rows(); ++t)
      for (int j = 0; j < 4; ++j)
        if (split.mesh.tets(t, j) == split.plus_faces(f, 0)) {
          Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
          for (int i = 0; i < 4; ++i) centroid += split.mesh.nodes.row(split.mesh.tets(t, i)).transpose() / 4.0;
          EXPECT_GT(n.dot(centroid - a), 0.0);
        }
  }
  // Groups: the crack replaced by its two sides; the others kept, still faces of the mesh.
  EXPECT_EQ(split.mesh.find_surface_group("cut_plane"), nullptr);
  ASSERT_NE(split.mesh.find_surface_group("cut_plane+"), nullptr);
  ASSERT_NE(split.mesh.find_surface_group("cut_plane-"), nullptr);
  const Eigen::MatrixXi boundary = boundary_faces(split.mesh.tets);
  std::set<std::array<int, 3>> boundary_keys;
  for (Eigen::Index b = 0; b < boundary.rows(); ++b) {
    std::array<int, 3> key{boundary(b, 0), boundary(b, 1), boundary(b, 2)};
    std::sort(key.begin(), key.end());
    boundary_keys.insert(key);
  }
  for (const char* name : {"support", "top", "sides", "cut_plane+", "cut_plane-"}) {
    const SurfaceGroup* g = split.mesh.find_surface_group(name);
    ASSERT_NE(g, nullptr) << name;
    for (Eigen::Index f = 0; f < g->triangles.rows(); ++f) {
      std::array<int, 3> key{g->triangles(f, 0), g->triangles(f, 1), g->triangles(f, 2)};
      std::sort(key.begin(), key.end());
      EXPECT_TRUE(boundary_keys.count(key)) << name << " triangle " << f << " is not a boundary face after the split";
    }
  }
  // Tetrahedra are not moved, only renumbered: no inverted elements.
  for (Eigen::Index t = 0; t < split.mesh.tets.rows(); ++t)
    EXPECT_GT(signed_volume(split.mesh.nodes.row(split.mesh.tets(t, 0)), split.mesh.nodes.row(split.mesh.tets(t, 1)),
                                split.mesh.nodes.row(split.mesh.tets(t, 2)), split.mesh.nodes.row(split.mesh.tets(t, 3))),
              0.0);
}

TEST(CrackSplit, CrackEndingInsideKeepsItsFrontShared) {
  // Box 4 x 3 x 4 with 4 x 3 x 4 cells; the crack on x = 2 covers z < 2 only (an edge crack from
  // the base). Grid nodes on x = 2: 4 (y) x 5 (z). Duplicated: those with z < 2 (z = 0, 1: 8
  // nodes); the front row z = 2 lies inside the body and stays shared, so the body stays one.
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 3, 4), 4, 3, 4);
  add_plane_group(mesh, 2.0, [](const Eigen::Vector3d& c) { return c.z() < 2.0; });
  const CrackSplit split = split_along_surface(mesh, "cut_plane");
  EXPECT_EQ(split.mesh.nodes.rows(), mesh.nodes.rows() + 8);
  EXPECT_EQ(face_connected_components(split.mesh.tets).maxCoeff(), 0);
  int shared = 0;
  for (Eigen::Index f = 0; f < split.plus_faces.rows(); ++f)
    for (int j = 0; j < 3; ++j)
      if (split.plus_faces(f, j) == split.minus_faces(f, j)) {
        ++shared;
        EXPECT_NEAR(split.mesh.nodes(split.plus_faces(f, j), 2), 2.0, 1e-12) << "only front nodes stay shared";
      }
  EXPECT_GT(shared, 0);
  EXPECT_NEAR(mesh_volume(split.mesh), 48.0, 1e-12);
}

TEST(CrackSplit, RefusesASurfaceThatIsNotInterior) {
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 2, 2), 2, 2, 2);
  EXPECT_THROW(split_along_surface(mesh, "support"), MeshError); // a boundary surface
  EXPECT_THROW(split_along_surface(mesh, "no_such_group"), MeshError);
}

} // namespace
} // namespace kerf
