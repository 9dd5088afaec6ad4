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

  /// For the segment translated along a fixed axis, [a + s e, a + d + s e] for s in [s_min,
  /// s_max] (e a unit vector): every s at which a tetrahedron's clipped interval can change form,
  /// appended to `out` (unsorted, with repeats). Between two consecutive ones each clip parameter
  /// t0, t1 of every tetrahedron is one affine function of s (the Cyrus–Beck parameters
  /// (offset − n·(a + s e))/(n·d) are affine in s; their max and min change form only where two of
  /// them, or one and 0 or 1, cross; a face parallel to the segment switches at one s), so each
  /// region's length is affine in s there: the candidates are those crossings, for the
  /// tetrahedra the swept segment's box meets. Allocates.
  void breakpoints_along(const Eigen::Vector3d& a, const Eigen::Vector3d& d, const Eigen::Vector3d& e, double s_min, double s_max,
                         std::vector<double>& out) const;

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

/// l_k(s) per region along a fixed cutting axis, computed once (a blade that moves along its
/// cutting direction only: paper 001's fixed cutting axis e_x): the edge's midpoint at p₀ + s e,
/// the segment [p₀ + s e − ½ L ê, p₀ + s e + ½ L ê]. Each region's length is affine in s between
/// the breakpoints `SegmentLengthInBody::breakpoints_along` finds (merged where closer than
/// 10⁻¹² m), so the table keeps, per interval, the line through two of its interior points
/// measured on the mesh. A length can jump at a breakpoint (an edge parallel to a face enters
/// the body all at once, and on the face the clipping's tolerance counts it on both sides), so
/// a query within 10⁻¹² m of one is measured on the mesh; any other equals the measurement to
/// round-off (the measurement's own tolerance, 10⁻¹² of a tetrahedron's size).
class ContactLengthTable {
public:
  ContactLengthTable() = default;
  /// Tabulates `body` (kept by reference, for the queries next to a breakpoint) along the axis
  /// p₀ + s e, s in [s_min, s_max], for the edge half-vector `half` (½ L ê). Allocates; takes
  /// two measurements per interval.
  ContactLengthTable(SegmentLengthInBody& body, const Eigen::Vector3d& p0, const Eigen::Vector3d& e, const Eigen::Vector3d& half,
                     double s_min, double s_max);

  [[nodiscard]] bool empty() const { return m_breakpoints.empty(); }
  [[nodiscard]] int intervals() const { return m_breakpoints.empty() ? 0 : static_cast<int>(m_breakpoints.size()) - 1; }
  /// The axis parameter of `p` when p lies on the axis (within 10⁻¹² m) and in the tabulated
  /// range, else NaN.
  [[nodiscard]] double parameter(const Eigen::Vector3d& p) const noexcept;
  /// Writes l_k(s) into `lengths` (one per region) and returns their sum. s in the range.
  /// Allocation-free; O(1) when s is in the interval of the previous query or next to it.
  double lengths(double s, std::span<double> lengths) noexcept;

private:
  SegmentLengthInBody* m_body = nullptr;
  Eigen::Vector3d m_p0 = Eigen::Vector3d::Zero(), m_e = Eigen::Vector3d::UnitX(), m_half = Eigen::Vector3d::Zero();
  int m_regions = 1;
  std::vector<double> m_breakpoints;    ///< ascending
  std::vector<double> m_value, m_slope; ///< per interval and region: l(b_j) + slope (s − b_j) inside
  std::size_t m_last = 0;               ///< the interval of the last query
};

} // namespace kerf
