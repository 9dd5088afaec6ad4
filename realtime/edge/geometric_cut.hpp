#pragma once
// Geometric cutting of paper 000 §3.2 (Figs. 8, 9): the tetrahedra crossed by the swept surface
// of the edge are divided on their cross points, each part re-tetrahedralised, the neighbour
// relation updated and the object split into fragments.

#include "meshes/tet_mesh.hpp"
#include "meshes/tet_quality.hpp" // signed_volume
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
  int cut_tets = 0;        ///< tetrahedra (as before the cut) divided
  int new_tets = 0;        ///< tetrahedra added (parts beyond the first of each divided one)
  int new_nodes = 0;       ///< cross points and the copies made when the crack opens
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

  /// Cuts along `surface` (paper 000 §3.2, Fig. 9). Every node near the surface gets the signed
  /// distance φ to the plane of its nearest patch; nodes within the snap tolerance of the surface
  /// are on it. Each tetrahedron edge whose ends lie on opposite sides gets a cross point where
  /// the linear interpolant of φ vanishes (t = φ_a / (φ_a - φ_b)) when that point lies on the
  /// swept surface (within `reach` x edge length) and at least the snap distance from both ends.
  /// Division: every tetrahedron around such an edge is bisected at its cross point
  /// (T -> T[a := p], T[b := p]: both keep T's orientation, volumes (1 - t) V and t V), so the
  /// mesh stays conforming without any rule that propagates; a tetrahedron whose crossing edges
  /// are all bisected ends as Fig. 8's two parts (tetrahedron + prism, two prisms, or with nodes
  /// on the surface tetrahedron + pyramid, two tetrahedra), already tetrahedralised. Opening: a
  /// face with its three corners on the surface between tetrahedra on opposite sides is cut
  /// through; around each surface node the tetrahedra joined through faces not cut through form
  /// groups, and each group beyond the first gets its own copy of the node.
  /// Cuts that end inside the body (progressive splitting): tetrahedra the surface only partly
  /// crosses are bisected at the cross points it reaches and keep their other crossing edges
  /// whole; they still join both sides around the front's nodes, so the crack is open behind the
  /// front and closed at it, and a later cut that continues the surface opens it further.
  /// Nodes and tetrahedra are only appended or re-pointed (original node indices and positions
  /// stay; surface groups keep their original faces); volume groups take the parts of their
  /// tetrahedra.
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

} // namespace kerf
