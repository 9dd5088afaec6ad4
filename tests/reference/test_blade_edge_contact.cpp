// Blade edge contact (reference/contact/): the point–triangle distance and its derivatives, the
// edge pass's forces, and a block pressed by a thin blade.
// 1. d² against a brute-force minimum over a fine barycentric grid (independent of the Voronoi
//    regions), and its gradient and Hessian against central differences, for points in the face,
//    edge and vertex regions.
// 2. A flat facet pair with the edge a depth δ below it: the force on the body is the closed form
//    ε_L δ L_in (L_in the edge length over the facets) into the body; the tangent matches central
//    differences of the force, also under a concave fold (the point's closest feature an edge).
// 3. A block pressed by a thin blade (0.1 mm, 15°, thinner than the body's quadrature-point
//    spacing): the force is positive, grows with depth, and equals minus the support reaction
//    (global balance of the body; no other load acts).

#include "reference/contact/blade_edge_contact.hpp"
#include "reference/contact/point_triangle_distance.hpp"
#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace kerf::reference {
namespace {

using Vec9 = Eigen::Matrix<double, 9, 1>;

double squared_distance(const Eigen::Vector3d& p, const Vec9& x) {
  return point_triangle_distance(p, x.segment<3>(0), x.segment<3>(3), x.segment<3>(6)).squared_distance;
}

PointTriangleDistance evaluate(const Eigen::Vector3d& p, const Vec9& x) {
  return point_triangle_distance(p, x.segment<3>(0), x.segment<3>(3), x.segment<3>(6));
}

TEST(PointTriangleDistance, MatchesBruteForceAndFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec9 x;
  x << 0, 0, 0, 1, 0.1, 0, 0.2, 0.9, 0.1;
  int seen[3] = {0, 0, 0};
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Vector3d p(1.5 * u(rng) + 0.4, 1.5 * u(rng) + 0.4, 0.6 * u(rng));
    const PointTriangleDistance d = evaluate(p, x);
    ++seen[static_cast<int>(d.feature)];
    // Brute force: min over a barycentric grid of step 1/400 (error O(step²) in d²).
    double brute = 1e300;
    const int n = 400;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double a = static_cast<double>(i) / n, b = static_cast<double>(j) / n;
        const Eigen::Vector3d y = (1 - a - b) * x.segment<3>(0) + a * x.segment<3>(3) + b * x.segment<3>(6);
        brute = std::min(brute, (p - y).squaredNorm());
      }
    EXPECT_NEAR(d.squared_distance, brute, 2e-5) << "trial " << trial;
    // Central differences, step h: truncation O(h²).
    const double h = 1e-6;
    for (int k = 0; k < 9; ++k) {
      Vec9 xp = x, xm = x;
      xp[k] += h;
      xm[k] -= h;
      EXPECT_NEAR(d.gradient[k], (squared_distance(p, xp) - squared_distance(p, xm)) / (2 * h), 1e-7)
          << "trial " << trial << " component " << k;
      const Vec9 column = (evaluate(p, xp).gradient - evaluate(p, xm).gradient) / (2 * h);
      for (int r = 0; r < 9; ++r)
        EXPECT_NEAR(d.hessian(r, k), column[r], 2e-6) << "trial " << trial << " entry " << r << "," << k;
    }
  }
  // The sweep visits every kind of feature.
  EXPECT_GT(seen[0], 0);
  EXPECT_GT(seen[1], 0);
  EXPECT_GT(seen[2], 0);
}

TEST(PointTriangleDistance, DegenerateTriangleIsRefused) {
  EXPECT_THROW(point_triangle_distance(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                       Eigen::Vector3d(2, 0, 0)),
               std::invalid_argument);
}

RigidToolShape blade_along_y(double length) {
  RigidToolShape b;
  b.kind = RigidToolShape::Kind::wedge;
  b.blade.edge_direction = Eigen::Vector3d::UnitY();
  b.blade.cutting_direction = -Eigen::Vector3d::UnitZ();
  b.blade.wedge_angle = 15.0 * std::numbers::pi / 180.0;
  b.blade.thickness = 1e-4;
  b.blade.edge_length = length;
  return b;
}

// A 1 × 1 m square in z = 0 as two facets, outward +z; nodes 0..3 at the corners.
struct Square {
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  std::vector<BoundaryFacet> facets{{0, 1, 2}, {0, 2, 3}};
};

TEST(BladeEdgeContact, FlatSurfaceGivesTheClosedFormLineLoad) {
  const Square sq;
  const std::vector<double> u(12, 0.0);
  BladeEdgeContactSettings s;
  s.line_penalty = 1e6;
  s.point_spacing = 0.01;
  s.search_distance = 0.5;
  const double delta = 1e-3;
  // The edge (1 m long, along y, centred at y = 0.5) lies δ below the square at x = 0.3. (The
  // square is an open surface: a point beside it but below its plane would count as inside,
  // which a closed body's side facets prevent; so the edge stays over the square.)
  const RigidToolShape blade = blade_along_y(1.0);
  const BladeEdgeContact c = blade_edge_contact(blade, Eigen::Vector3d(0.3, 0.5, -delta), sq.facets, sq.X, u, s);
  // f = ε_L δ L_in along −n: the surface is pushed into the body, L_in = 1 m (point spacing
  // divides it, trapezoid weights).
  EXPECT_EQ(c.active_points, 101);
  EXPECT_NEAR(c.force_on_body.z(), -s.line_penalty * delta * 1.0, 1e-9 * s.line_penalty * delta);
  EXPECT_NEAR(c.force_on_body.head<2>().norm(), 0.0, 1e-12 * s.line_penalty * delta);
  EXPECT_NEAR(c.max_line_load, s.line_penalty * delta, 1e-9);
  // Above the surface: no contact.
  EXPECT_EQ(blade_edge_contact(blade, Eigen::Vector3d(0.3, 0.5, delta), sq.facets, sq.X, u, s).active_points, 0);
}

// Σ over the terms of the force on each node (12 entries: four nodes × 3).
Eigen::VectorXd nodal_force(const BladeEdgeContact& c) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(12);
  for (const EdgeContactTerm& t : c.terms)
    for (int i = 0; i < 9; ++i) f[3 * t.nodes[static_cast<std::size_t>(i / 3)] + i % 3] += t.force_on_body[i];
  return f;
}

TEST(BladeEdgeContact, TangentMatchesFiniteDifferencesOnAFold) {
  Square sq;
  // Fold the square along its diagonal 0–2 into a concave groove (corners 1 and 3 raised): an
  // edge point under the diagonal has the shared edge as its closest feature in both facets.
  std::vector<double> u(12, 0.0);
  u[3 * 1 + 2] = 0.2;
  u[3 * 3 + 2] = 0.2;
  BladeEdgeContactSettings s;
  s.line_penalty = 1e6;
  s.point_spacing = 0.05;
  s.search_distance = 0.5;
  for (const auto& [edge, where] : {std::pair{Eigen::Vector3d(1, 1, 0).normalized(), Eigen::Vector3d(0.5, 0.5, -0.02)},
                                    std::pair{Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.6, 0.5, 0.047)}}) {
    // (0.047, not 0.05: no edge point may sit exactly on the surface, where W is only C¹ and a
    // central difference straddles the kink of the tangent.)
    RigidToolShape blade = blade_along_y(0.6);
    blade.blade.edge_direction = edge;
    blade.blade.cutting_direction = Eigen::Vector3d(0, 0, -1);
    const BladeEdgeContact c = blade_edge_contact(blade, where, sq.facets, sq.X, u, s);
    ASSERT_GT(c.active_points, 0);
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(12, 12);
    for (const EdgeContactTerm& t : c.terms)
      for (int i = 0; i < 9; ++i)
        for (int j = 0; j < 9; ++j)
          K(3 * t.nodes[static_cast<std::size_t>(i / 3)] + i % 3, 3 * t.nodes[static_cast<std::size_t>(j / 3)] + j % 3) +=
              t.stiffness(i, j);
    const double h = 1e-8;
    for (int k = 0; k < 12; ++k) {
      std::vector<double> up = u, um = u;
      up[static_cast<std::size_t>(k)] += h;
      um[static_cast<std::size_t>(k)] -= h;
      // ∂f/∂x = −∂²W/∂x²
      const Eigen::VectorXd column = (nodal_force(blade_edge_contact(blade, where, sq.facets, sq.X, up, s)) -
                                      nodal_force(blade_edge_contact(blade, where, sq.facets, sq.X, um, s))) /
                                     (2 * h);
      for (int r = 0; r < 12; ++r)
        EXPECT_NEAR(-K(r, k), column[r], 1e-5 * s.line_penalty) << "entry " << r << "," << k;
    }
  }
}

TEST(BladeEdgeContact, ThinBladeIndentsABlock) {
  // 20 × 20 × 10 mm block, 5 × 5 × 3 cells (4 mm facets, 25× the blade's 0.16 mm width at
  // 0.6 mm depth): the flanks meet no boundary quadrature point, only the edge pass acts.
  const double L = 0.02;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d(-L / 2, -L / 2, 0), Eigen::Vector3d(L / 2, L / 2, L / 2), 5, 5, 3);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.tool = blade_along_y(0.03);
  SolverSettings settings;
  settings.edge_point_spacing = 0.5e-3;
  FiniteStrainSolver solver(p, settings);
  double previous = 0.0;
  for (double depth : {0.2e-3, 0.4e-3, 0.6e-3}) {
    const EquilibriumReport r = solver.solve({0.0, Eigen::Vector3d(0.4e-3, 0, L / 2 - depth)});
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_EQ(r.contact_points, 0);
    EXPECT_GT(r.edge_contact_points, 0);
    // The edge spans the block's width, to the point spacing at either side.
    EXPECT_NEAR(r.edge_contact_length, L, 1.01e-3);
    EXPECT_GT(r.tool_force.z(), previous);        // the body pushes the blade back up, more with depth
    previous = r.tool_force.z();
    ASSERT_EQ(r.boundary_reactions.size(), 1u);
    EXPECT_LT((r.tool_force + r.support_reaction).norm(), 1e-8 * r.tool_force.norm());
    EXPECT_LT(r.force_imbalance.norm(), 1e-8 * r.tool_force.norm());
  }
}

} // namespace
} // namespace kerf::reference
