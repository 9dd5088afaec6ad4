// Tests of meshes/surface_mesh: the boundary of structured Kuhn meshes (a box and a non-convex
// L-shaped block) against analytic volumes and areas, and SurfaceQuery against brute force
// (closest point over all triangles, containment by point location in the tetrahedra).
#include "meshes/surface_mesh.hpp"

#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <new>
#include <random>

// Counts heap allocations while `g_counting` is set, to check that queries allocate nothing.
// malloc itself is interposed (operator new and Eigen both end up there); glibc exports the
// real allocator as __libc_malloc. Not under AddressSanitizer, which owns malloc.
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
} // namespace

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#define KERF_COUNT_MALLOC 1
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* malloc(std::size_t size) noexcept {
  if (g_counting) ++g_allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  if (g_counting) ++g_allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  if (g_counting) ++g_allocations;
  return __libc_realloc(p, size);
}
}
#endif

namespace kerf {
namespace {

using Vec = Eigen::Vector3d;

/// Structured mesh of the box [0, size.x] x [-size.y/2, size.y/2] x [0, size.z] with n cells per
/// axis, each cell split into 6 Kuhn tetrahedra (conforming across cells); cells for which
/// `keep(i, j, k)` is false are left out.
template <class Keep> TetMesh kuhn_grid(const Vec& size, const std::array<int, 3>& n, Keep&& keep) {
  TetMesh mesh;
  const auto node = [&](int i, int j, int k) { return i + (n[0] + 1) * (j + (n[1] + 1) * k); };
  mesh.nodes.resize((n[0] + 1) * (n[1] + 1) * (n[2] + 1), 3);
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
        mesh.nodes.row(node(i, j, k)) << size.x() * i / n[0], size.y() * j / n[1] - size.y() / 2, size.z() * k / n[2];
  const std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<std::array<int, 4>> tets;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (!keep(i, j, k)) continue;
        for (const auto& order : orders) {
          std::array<int, 3> c{i, j, k};
          std::array<int, 4> tet{};
          tet[0] = node(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])];
            tet[static_cast<std::size_t>(s + 1)] = node(c[0], c[1], c[2]);
          }
          if (signed_volume(mesh.nodes.row(tet[0]).transpose(), mesh.nodes.row(tet[1]).transpose(),
                            mesh.nodes.row(tet[2]).transpose(), mesh.nodes.row(tet[3]).transpose()) < 0)
            std::swap(tet[2], tet[3]);
          tets.push_back(tet);
        }
      }
  mesh.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j) mesh.tets(static_cast<Eigen::Index>(t), j) = tets[t][static_cast<std::size_t>(j)];
  return mesh;
}

const Vec k_box(0.040, 0.020, 0.015);

TetMesh box_mesh() {
  return kuhn_grid(k_box, {8, 4, 3}, [](int, int, int) { return true; });
}

/// The box without the cells i >= 4, k >= 1 (a step: non-convex, with concave edges and vertices).
TetMesh l_block_mesh() {
  return kuhn_grid(k_box, {8, 4, 3}, [](int i, int, int k) { return i < 4 || k < 1; });
}

/// Brute force: the smallest distance from p to any triangle, by projecting onto the plane
/// when inside the triangle and otherwise clamping to the three edges (a second method,
/// independent of the Voronoi-region code under test).
double brute_force_distance(const SurfaceMesh& s, const Vec& p) {
  double best = std::numeric_limits<double>::infinity();
  const auto segment = [&](const Vec& a, const Vec& b) {
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    return (a + t * (b - a) - p).norm();
  };
  for (Eigen::Index f = 0; f < s.triangles.rows(); ++f) {
    const Vec a = s.vertices.row(s.triangles(f, 0)).transpose();
    const Vec b = s.vertices.row(s.triangles(f, 1)).transpose();
    const Vec c = s.vertices.row(s.triangles(f, 2)).transpose();
    const Vec n = (b - a).cross(c - a).normalized();
    const Vec q = p - n.dot(p - a) * n;
    const bool inside = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 && (a - c).cross(q - c).dot(n) >= 0;
    const double d = inside ? std::abs(n.dot(p - a)) : std::min({segment(a, b), segment(b, c), segment(c, a)});
    best = std::min(best, d);
  }
  return best;
}

/// Point location: p is inside the body if its barycentric coordinates in some tetrahedron are
/// all non-negative.
bool inside_some_tet(const TetMesh& m, const Vec& p) {
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    const Vec a = m.nodes.row(m.tets(t, 0)).transpose();
    Eigen::Matrix3d J;
    for (int j = 0; j < 3; ++j) J.col(j) = m.nodes.row(m.tets(t, j + 1)).transpose() - a;
    const Vec lambda = J.inverse() * (p - a);
    if (lambda.minCoeff() >= 0.0 && lambda.sum() <= 1.0) return true;
  }
  return false;
}

TEST(SurfaceMesh, BoundaryIsClosedAndEnclosesTheMeshVolume) {
  for (const TetMesh& mesh : {box_mesh(), l_block_mesh()}) {
    const SurfaceMesh surface = boundary_surface(mesh);
    // Divergence theorem on the closed boundary = sum of the tetrahedron volumes.
    EXPECT_NEAR(enclosed_volume(surface), mesh_volume(mesh), 1e-9 * mesh_volume(mesh));
    // Every edge is shared by exactly two boundary triangles with opposite directions (closed,
    // consistently oriented 2-manifold).
    std::map<std::pair<int, int>, int> directed;
    for (Eigen::Index f = 0; f < surface.triangles.rows(); ++f)
      for (int j = 0; j < 3; ++j) ++directed[{surface.triangles(f, j), surface.triangles(f, (j + 1) % 3)}];
    for (const auto& [edge, count] : directed) {
      EXPECT_EQ(count, 1);
      EXPECT_EQ(directed.count({edge.second, edge.first}), 1U);
    }
  }
  // Analytic: the box volume and area.
  const SurfaceMesh box = boundary_surface(box_mesh());
  const double volume = k_box.x() * k_box.y() * k_box.z();
  EXPECT_NEAR(enclosed_volume(box), volume, 1e-12 * volume);
  const double area = 2 * (k_box.x() * k_box.y() + k_box.y() * k_box.z() + k_box.z() * k_box.x());
  EXPECT_NEAR(surface_area(box), area, 1e-12 * area);
  // Analytic: the L block is the box minus half its length times two thirds of its depth.
  const double l_volume = volume - (k_box.x() / 2) * k_box.y() * (2 * k_box.z() / 3);
  EXPECT_NEAR(enclosed_volume(boundary_surface(l_block_mesh())), l_volume, 1e-12 * l_volume);
}

TEST(SurfaceQuery, ClosestPointMatchesBruteForceAndContainsMatchesPointLocation) {
  std::mt19937 random(2024);
  for (const TetMesh& mesh : {box_mesh(), l_block_mesh()}) {
    const SurfaceQuery query(boundary_surface(mesh));
    const SurfaceMesh& surface = query.surface();
    // Random points in the bounding box grown by 30 % on every side.
    std::uniform_real_distribution<double> ux(-0.3 * k_box.x(), 1.3 * k_box.x());
    std::uniform_real_distribution<double> uy(-0.8 * k_box.y(), 0.8 * k_box.y());
    std::uniform_real_distribution<double> uz(-0.3 * k_box.z(), 1.3 * k_box.z());
    int inside_count = 0;
    for (int n = 0; n < 400; ++n) {
      const Vec p(ux(random), uy(random), uz(random));
      const SurfaceQuery::Closest closest = query.closest_point(p);
      const double reference = brute_force_distance(surface, p);
      EXPECT_NEAR(std::abs(closest.signed_distance), reference, 1e-12 * reference + 1e-18);
      EXPECT_NEAR((closest.point - p).norm(), reference, 1e-12 * reference + 1e-18);
      EXPECT_NEAR(closest.normal.norm(), 1.0, 1e-12);
      ASSERT_GE(closest.triangle, 0);
      if (reference < 1e-9) continue; // too close to the surface for a meaningful inside/outside
      const bool inside = inside_some_tet(mesh, p);
      inside_count += inside;
      EXPECT_EQ(query.contains(p), inside) << "p = " << p.transpose();
      EXPECT_EQ(closest.signed_distance < 0.0, inside);
    }
    EXPECT_GT(inside_count, 50); // the sample really tests both answers
  }
}

TEST(SurfaceQuery, VerticesEdgesAndFacesOfTheBox) {
  const SurfaceQuery query(boundary_surface(box_mesh()));
  const Vec lo(0, -k_box.y() / 2, 0);
  const Vec hi(k_box.x(), k_box.y() / 2, k_box.z());
  const auto finite = [](const SurfaceQuery::Closest& c) {
    return c.point.allFinite() && c.normal.allFinite() && std::isfinite(c.signed_distance);
  };
  // Points exactly on the surface: corners, edge midpoints, face centres, grid vertices.
  for (int corner = 0; corner < 8; ++corner) {
    const Vec p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(), (corner & 4) ? hi.z() : lo.z());
    const auto c = query.closest_point(p);
    EXPECT_TRUE(finite(c));
    EXPECT_EQ(c.signed_distance, 0.0);
    EXPECT_FALSE(query.contains(p));
    // Angle-weighted pseudo-normal at a box corner: three faces each with weight pi/2, so
    // n = (+-1, +-1, +-1)/sqrt 3 whatever the triangulation (Bærentzen & Aanæs 2005, eq. 2).
    const Vec diagonal((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
    EXPECT_NEAR((c.normal - diagonal / std::sqrt(3.0)).norm(), 0.0, 1e-12);
    // Outside along the diagonal: the corner is the closest point, at distance |offset|.
    const auto out = query.closest_point(p + 1e-3 * diagonal);
    EXPECT_NEAR((out.point - p).norm(), 0.0, 1e-15);
    EXPECT_NEAR(out.signed_distance, 1e-3 * std::sqrt(3.0), 1e-15);
    // Inside along the diagonal: negative, distance to the nearest of the three faces.
    EXPECT_NEAR(query.closest_point(p - 1e-4 * diagonal).signed_distance, -1e-4, 1e-15);
  }
  const Vec centre = 0.5 * (lo + hi);
  EXPECT_NEAR(query.closest_point(centre).signed_distance, -k_box.z() / 2, 1e-15); // nearest faces z = 0, z = depth
  for (const Vec& p : {Vec(centre.x(), lo.y(), lo.z()), Vec(lo.x(), centre.y(), hi.z()), Vec(centre.x(), centre.y(), lo.z()),
                       Vec(0.005, 0.0, hi.z()), Vec(0.01, hi.y(), 0.005), Vec(0.0123, 0.0031, hi.z()),
                       Vec(0.0123, lo.y(), lo.z()), Vec(hi.x(), 0.0031, 0.0077)}) {
    // Exactly on the surface (grid vertices, edge and face interiors): distance 0 up to the
    // rounding of the projection, never NaN.
    const auto c = query.closest_point(p);
    EXPECT_TRUE(finite(c));
    EXPECT_NEAR(c.signed_distance, 0.0, 1e-17);
    EXPECT_NEAR((c.point - p).norm(), 0.0, 1e-17);
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
  }
  // An edge point pushed out along the bisector: distance equals the offset, sign positive.
  const Vec edge(centre.x(), lo.y(), lo.z());
  const auto c = query.closest_point(edge + 1e-3 * Vec(0, -1, -1).normalized());
  EXPECT_NEAR(c.signed_distance, 1e-3, 1e-15);
  EXPECT_NEAR((c.normal - Vec(0, -1, -1).normalized()).norm(), 0.0, 1e-12);
}

TEST(SurfaceQuery, ConcaveEdgeOfTheLBlock) {
  // The L block's concave edge runs along y at x = length/2, z = depth/3. A point just inside,
  // off the bisector, must be inside; a point in the removed notch must be outside.
  const SurfaceQuery query(boundary_surface(l_block_mesh()));
  const double x = k_box.x() / 2;
  const double z = k_box.z() / 3;
  EXPECT_TRUE(query.contains(Vec(x - 1e-4, 0.001, z + 2e-4)));
  EXPECT_TRUE(query.contains(Vec(x + 2e-4, 0.001, z - 1e-4)));
  EXPECT_FALSE(query.contains(Vec(x + 1e-4, 0.001, z + 1e-4)));
  const auto on_edge = query.closest_point(Vec(x, 0.0, z));
  EXPECT_EQ(on_edge.signed_distance, 0.0);
  EXPECT_TRUE(on_edge.normal.allFinite());
}

TEST(SurfaceQuery, QueriesAllocateNothing) {
#ifndef KERF_COUNT_MALLOC
  GTEST_SKIP() << "malloc is not interposable in this build";
#endif
  const SurfaceQuery query(boundary_surface(l_block_mesh()));
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(-0.01, 0.05);
  std::vector<Vec> points;
  for (int n = 0; n < 200; ++n) points.emplace_back(u(random), u(random) - 0.02, u(random));
  double sum = 0.0;
  // Sanity check of the counter itself: one allocation is seen.
  g_allocations = 0;
  g_counting = true;
  auto* probe = new std::vector<double>(16);
  g_counting = false;
  delete probe;
  ASSERT_GE(g_allocations.load(), 1);
  g_allocations = 0;
  g_counting = true;
  for (const Vec& p : points) {
    sum += query.closest_point(p).signed_distance;
    sum += query.contains(p) ? 1.0 : 0.0;
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(SurfaceQuery, EmptySurface) {
  const SurfaceQuery query;
  const auto c = query.closest_point(Vec(1, 2, 3));
  EXPECT_EQ(c.triangle, -1);
  EXPECT_FALSE(query.contains(Vec(1, 2, 3)));
}

} // namespace
} // namespace kerf
