// Tests of meshes/triangle_closest_point: the closest point on the right triangle a = 0, b = x̂,
// c = ŷ of points in each of its seven Voronoi regions, worked out by hand (a point above the
// triangle projects onto it; a point beside an edge projects onto the edge; a point beyond a vertex
// meets the vertex), and a flat triangle that must not give NaN.
#include "meshes/triangle_closest_point.hpp"

#include <gtest/gtest.h>

namespace kerf {
namespace {

const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);

void expect_closest(const Eigen::Vector3d& p, const Eigen::Vector3d& expected, TriangleFeature feature) {
  const TriangleClosestPoint q = closest_point_on_triangle(p, a, b, c);
  EXPECT_TRUE(q.point.isApprox(expected, 1e-15) || (q.point - expected).norm() < 1e-15) << q.point.transpose();
  EXPECT_EQ(q.feature, feature);
  // The barycentric coordinates give the same point and sum to one.
  const Eigen::Vector3d from_barycentric = q.barycentric[0] * a + q.barycentric[1] * b + q.barycentric[2] * c;
  EXPECT_NEAR((from_barycentric - q.point).norm(), 0.0, 1e-15);
  EXPECT_NEAR(q.barycentric[0] + q.barycentric[1] + q.barycentric[2], 1.0, 1e-15);
}

TEST(TriangleClosestPoint, EveryVoronoiRegion) {
  expect_closest({0.2, 0.2, 3}, {0.2, 0.2, 0}, TriangleFeature::face);
  expect_closest({0.5, -1, 0}, {0.5, 0, 0}, TriangleFeature::edge_ab);
  expect_closest({-1, 0.3, 2}, {0, 0.3, 0}, TriangleFeature::edge_ca);
  expect_closest({1, 1, -1}, {0.5, 0.5, 0}, TriangleFeature::edge_bc);
  expect_closest({-1, -1, 0}, a, TriangleFeature::vertex_a);
  expect_closest({2, -0.5, 1}, b, TriangleFeature::vertex_b);
  expect_closest({-0.5, 2, 1}, c, TriangleFeature::vertex_c);
}

TEST(TriangleClosestPoint, FlatTriangleGivesAFinitePoint) {
  // Three collinear vertices: the closest point lies on the segment, never NaN.
  const Eigen::Vector3d x0(0, 0, 0), x1(1, 0, 0), x2(2, 0, 0);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.5, 1, 0), Eigen::Vector3d(1.5, 0, 1), Eigen::Vector3d(1, 0, 0)}) {
    const TriangleClosestPoint q = closest_point_on_triangle(p, x0, x1, x2);
    ASSERT_TRUE(q.point.allFinite());
    EXPECT_NEAR(q.point.y(), 0.0, 1e-15);
    EXPECT_NEAR(q.point.z(), 0.0, 1e-15);
  }
}

} // namespace
} // namespace kerf
