#pragma once
// SurfaceMesh: the boundary triangles of a body, with the closest-point and inside/outside
// queries the realtime side needs (collision of a tool with the body, pruning cells outside it).

#include "meshes/aabb_tree.hpp"
#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>

namespace kerf {

/// A closed triangle surface. Units: metres. Triangles are oriented with outward normals.
struct SurfaceMesh {
  Eigen::MatrixXd vertices;  ///< #V by 3
  Eigen::MatrixXi triangles; ///< #F by 3 indices into vertices, outward (b-a)x(c-a)
};

/// The boundary surface of a tetrahedral mesh (the faces that belong to one tetrahedron),
/// re-indexed to its own compact vertex list, outward oriented.
SurfaceMesh boundary_surface(const TetMesh& mesh);

/// Total area [m^2].
double surface_area(const SurfaceMesh& surface);

/// Volume enclosed by a closed, outward-oriented surface, by the divergence theorem [m^3].
double enclosed_volume(const SurfaceMesh& surface);

/// Closest-point and containment queries on a closed surface, built once (AABB tree and the
/// angle-weighted pseudo-normals of Bærentzen & Aanæs, "Signed distance computation using the
/// angle weighted pseudonormal", IEEE TVCG 11(3), 2005), then answered without allocation.
class SurfaceQuery {
public:
  /// Result of a closest-point query.
  struct Closest {
    Eigen::Vector3d point = Eigen::Vector3d::Zero(); ///< closest point on the surface
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(); ///< outward pseudo-normal at that point (unit)
    double signed_distance = 0.0; ///< [m], negative inside the body
    int triangle = -1;            ///< triangle holding the closest point
  };

  SurfaceQuery() = default;
  explicit SurfaceQuery(SurfaceMesh surface);

  [[nodiscard]] const SurfaceMesh& surface() const { return m_surface; }

  /// Closest point on the surface to `p`, its outward pseudo-normal and the signed distance.
  /// Sign from the angle-weighted pseudo-normal of the closest feature (face, edge or vertex),
  /// which is exact for closed 2-manifold surfaces (Bærentzen & Aanæs 2005, Theorem 1).
  [[nodiscard]] Closest closest_point(const Eigen::Vector3d& p) const;

  /// True if `p` lies inside the closed surface (signed distance < 0).
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const;

private:
  SurfaceMesh m_surface;
  AabbTree m_tree;
  Eigen::MatrixXd m_face_normals;   ///< #F by 3, unit
  Eigen::MatrixXd m_vertex_normals; ///< #V by 3, angle-weighted, unit
  /// #F*3 by 3: row 3 f + k is the pseudo-normal of the edge of triangle f opposite its local
  /// vertex k (the normalised sum of the unit normals of the two triangles sharing that edge).
  Eigen::MatrixXd m_edge_normals;
};

} // namespace kerf
