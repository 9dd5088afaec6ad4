#pragma once
// The closest point on a triangle to a point, and the feature (vertex, edge or face) that holds it
// (Ericson, "Real-Time Collision Detection", 2005, §5.1.5, ClosestPtPointTriangle).

#include <Eigen/Core>

#include <array>

namespace kerf {

/// Which feature of a triangle (a, b, c) holds the closest point: a vertex, the edge opposite a
/// local vertex (edge_bc is opposite a), or the interior.
enum class TriangleFeature { vertex_a, vertex_b, vertex_c, edge_bc, edge_ca, edge_ab, face };

/// The closest point on a triangle (a, b, c), the feature it lies on, and its barycentric
/// coordinates: point = u a + v b + w c, (u, v, w) = `barycentric`, with exact zeros (and ones) off
/// the feature.
struct TriangleClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  TriangleFeature feature = TriangleFeature::face;
  std::array<double, 3> barycentric{1.0, 0.0, 0.0};
};

/// Closest point on the triangle (a, b, c) to p, by the Voronoi-region tests of Ericson (2005)
/// §5.1.5: the dot products d1..d6 of the edges with p's offsets from the vertices decide the
/// region without any division until the region is known; in the interior the point is
/// a + v (b − a) + w (c − a) with (v, w) = (vb, vc) / (va + vb + vc).
/// A degenerate (numerically flat) triangle falls into a vertex or edge region, or to vertex a:
/// never NaN for finite input. Inline: SurfaceQuery::closest_point calls it per triangle in the
/// servo loop.
inline TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                      const Eigen::Vector3d& b, const Eigen::Vector3d& c) noexcept {
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, TriangleFeature::vertex_a, {1.0, 0.0, 0.0}};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, TriangleFeature::vertex_b, {0.0, 1.0, 0.0}};
  // Edge region AB: vc = d1 d4 - d3 d2 <= 0, projection parameter v = d1 / (d1 - d3).
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {a + v * ab, TriangleFeature::edge_ab, {1.0 - v, v, 0.0}};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, TriangleFeature::vertex_c, {0.0, 0.0, 1.0}};
  // Edge region AC: vb = d5 d2 - d1 d6 <= 0, w = d2 / (d2 - d6).
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {a + w * ac, TriangleFeature::edge_ca, {1.0 - w, 0.0, w}};
  }
  // Edge region BC: va = d3 d6 - d5 d4 <= 0, w = (d4 - d3) / ((d4 - d3) + (d5 - d6)).
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), TriangleFeature::edge_bc, {0.0, 1.0 - w, w}};
  }
  // Interior: barycentric (u, v, w) = (va, vb, vc) / (va + vb + vc).
  const double sum = va + vb + vc;
  // Only reachable for a numerically flat triangle: fall back to vertex a.
  if (!(sum > 0.0)) return {a, TriangleFeature::vertex_a, {1.0, 0.0, 0.0}};
  const double inverse = 1.0 / sum;
  const double v = vb * inverse, w = vc * inverse;
  return {a + ab * v + ac * w, TriangleFeature::face, {1.0 - v - w, v, w}};
}

} // namespace kerf
