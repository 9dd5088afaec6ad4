#pragma once
// Geometric cutting of paper 000 §3.2 (Figs. 8, 9): the tetrahedra crossed by the swept surface
// of the edge are divided on their cross points, each part re-tetrahedralised, the neighbour
// relation updated and the object split into fragments.

#include "meshes/tet_mesh.hpp"
#include "realtime/edge/swept_surface.hpp"

#include <Eigen/Core>

#include <vector>

namespace kerf {

/// Tolerances of the geometric cut, relative to the mean edge length h of the tetrahedra near
/// the surface.
struct GeometricCutOptions {
  /// Nodes closer than snap_tolerance * h to the surface are put on it (their cross points
  /// coincide with the node), so no part thinner than that is made: the smallest part of a cut
  /// tetrahedron then has a volume above ~snap_tolerance^3 of it, far above rounding.
  double snap_tolerance = 1e-4;
  /// A cross point on a tetrahedron edge counts when it lies within reach * (edge length) of the
  /// swept surface (the surface is approximated by its linear interpolant on the mesh).
  double reach = 0.25;
};

/// What one cut did.
struct GeometricCutReport {
  int cut_tets = 0;        ///< tetrahedra divided
  int new_tets = 0;        ///< tetrahedra added (parts beyond the first of each divided one)
  int new_nodes = 0;       ///< cross points (two copies each, one per side) and node copies
  int snapped_nodes = 0;   ///< nodes put on the surface by snap_tolerance
  int fragments = 0;       ///< connected parts of the object after the cut
  double min_volume_ratio = 0.0; ///< smallest (part volume / parent volume) over the parts made
};

/// A tetrahedral object that can be cut: the mesh, its face adjacency, and its fragments.
/// Cutting allocates and runs off the servo thread (see docs/models.md, "edge").
class CuttableBody {
public:
  /// Takes the mesh (every tetrahedron positively oriented) and builds its adjacency.
  explicit CuttableBody(TetMesh mesh);

  /// Cuts along `surface`: every tetrahedron edge crossing the surface gets a cross point, where
  /// the linear interpolant of the nodes' signed distances φ to the surface vanishes
  /// (t = φ_a / (φ_a - φ_b)); nodes with |φ| below the snap tolerance are on the surface. A
  /// tetrahedron is divided when every one of its edges whose ends lie on opposite sides has a
  /// cross point on the surface (Fig. 8: one node apart gives a tetrahedron and a prism, two
  /// apart two prisms, with nodes on the surface a tetrahedron and a pyramid, or two
  /// tetrahedra); a tetrahedron the surface only partly crosses (where the cut ends) is left
  /// whole, and so are its edges, so the mesh stays conforming. That rule propagates through
  /// shared edges: a surface that ends inside the body (a partial cut, no separation) divides
  /// nothing; only cuts that run through the body are applied. Each part is a convex polyhedron,
  /// split into tetrahedra by coning from its lowest-numbered node over its faces, each face
  /// split from its own lowest-numbered node, so that shared faces split alike. Cross points and
  /// surface nodes whose surroundings are all divided get one copy per side: the sides separate.
  GeometricCutReport cut(const SweptSurface& surface, const GeometricCutOptions& options = {});

  [[nodiscard]] const TetMesh& mesh() const { return m_mesh; }
  /// #T by 4: entry (t, k) is the tetrahedron across the face opposite local node k, or -1.
  [[nodiscard]] const Eigen::MatrixXi& adjacency() const { return m_adjacency; }
  /// Fragment index of each tetrahedron (connected through shared faces).
  [[nodiscard]] const std::vector<int>& fragment_of_tet() const { return m_fragment; }
  [[nodiscard]] int fragment_count() const { return m_fragment_count; }
  /// Volume of each fragment [m^3].
  [[nodiscard]] std::vector<double> fragment_volumes() const;

private:
  void label_fragments();

  TetMesh m_mesh;
  Eigen::MatrixXi m_adjacency;
  std::vector<int> m_fragment;
  int m_fragment_count = 0;
};

/// Signed volume of the tetrahedron (a, b, c, d): det[b - a, c - a, d - a] / 6 [m^3].
double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d);

} // namespace kerf
