#pragma once
// Contact length l(x) of paper 001 (Eqs. 7, 8, 10): the length of the blade's edge that lies
// inside the body at the edge's current position, measured on the scene's tetrahedral mesh —
// per region, so a layered body (paper 001 §6) gets one length per layer.

#include "meshes/aabb_tree.hpp"
#include "meshes/tet_mesh.hpp"

#include <Eigen/Core>

#include <span>
#include <string>
#include <vector>

namespace kerf {

/// Length of a segment inside a tetrahedral body, per region.
///
/// The segment a + t (b - a), t in [0, 1], is clipped against each candidate tetrahedron
/// (Cyrus–Beck clipping against its four face planes, closed with a tolerance of 1e-12 of the
/// tetrahedron's size so that a segment lying in a shared face — a blade edge travelling in the
/// conforming `cut_plane` — is counted), and the parameter intervals of each region are merged
/// (their union), so shared faces are never counted twice:
///   l_k = |b - a| * measure( union over tets T in region k of [t0_T, t1_T] ).
/// Candidates come from an AABB tree over the tetrahedra. `lengths` allocates nothing: its
/// scratch space is sized at construction. One query at a time per object (not thread-safe).
class SegmentLengthInBody {
public:
  /// `regions`: names of volume groups that split the body into regions (e.g. layer_upper,
  /// layer_lower); empty means one region, the whole mesh. Throws MeshError if a named group is
  /// missing or if some tetrahedron belongs to none of them.
  explicit SegmentLengthInBody(const TetMesh& mesh, const std::vector<std::string>& regions = {});

  [[nodiscard]] int region_count() const { return m_region_count; }

  /// Writes the length [m] of the segment [a, b] inside each region into `lengths`
  /// (size region_count()) and returns their sum.
  double lengths(const Eigen::Vector3d& a, const Eigen::Vector3d& b, std::span<double> lengths);

  /// Total length of [a, b] inside the body [m].
  double length(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

private:
  struct Interval {
    double t0, t1;
  };
  struct Face {
    Eigen::Vector3d normal; ///< outward unit normal
    double offset;          ///< normal . x <= offset inside
  };

  std::vector<std::array<Face, 4>> m_faces; ///< per tetrahedron
  std::vector<double> m_tolerance;          ///< per tetrahedron, absolute [m]
  std::vector<int> m_region;                ///< per tetrahedron
  int m_region_count = 1;
  AabbTree m_tree;
  std::vector<std::vector<Interval>> m_scratch; ///< per region, capacity = its tet count
};

} // namespace kerf
