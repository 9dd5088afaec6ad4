// Rigid-tool penalty contact: the tool geometry against hand-computed distances, and the
// equilibrium of a block pressed by the sphere — the contact resultant on the tool equals minus
// the support reaction (global force balance, Newton's third law; no other load acts).

#include "reference/finite_strain_solver.hpp"
#include "reference/rigid_tool.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>

namespace kerf::reference {
namespace {

TEST(RigidTool, SpherePenetrationAndNormal) {
  RigidToolShape s;
  s.radius = 2e-3;
  const ToolContactPoint c = tool_contact(s, Eigen::Vector3d(0, 0, 2.5e-3), Eigen::Vector3d(0, 0, 1e-3));
  ASSERT_TRUE(c.inside);
  EXPECT_NEAR(c.penetration, 0.5e-3, 1e-15); // R − |x − c| = 2 − 1.5 mm
  EXPECT_NEAR((c.normal - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-15);
  EXPECT_FALSE(tool_contact(s, Eigen::Vector3d(0, 0, 2.5e-3), Eigen::Vector3d(0, 0, 0.4e-3)).inside);
}

TEST(RigidTool, WedgeNearestExit) {
  RigidToolShape w;
  w.kind = RigidToolShape::Kind::wedge;
  w.blade.wedge_angle = std::numbers::pi / 2.0; // 90°: flanks at 45°
  w.blade.thickness = 10e-3;
  // Edge along y at the origin cutting down (−z): a point 1 mm above the edge on its axis is
  // inside, nearest exit through a flank at distance 1 mm · sin 45°.
  const ToolContactPoint c = tool_contact(w, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1e-3));
  ASSERT_TRUE(c.inside);
  EXPECT_NEAR(c.penetration, 1e-3 * std::sin(std::numbers::pi / 4.0), 1e-15);
  EXPECT_NEAR(std::abs(c.normal.z()), std::sin(std::numbers::pi / 4.0), 1e-12);
  // Ahead of the edge (below it) is outside.
  EXPECT_FALSE(tool_contact(w, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -1e-4)).inside);
  RigidToolShape bad = w;
  bad.blade.wedge_angle = 0.0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

TEST(RigidTool, WedgePushesACrackFaceToItsOwnSide) {
  RigidToolShape w;
  w.kind = RigidToolShape::Kind::wedge;
  w.blade.wedge_angle = std::numbers::pi / 2.0; // flanks at 45°
  w.blade.thickness = 10e-3;
  // Edge along y cutting down (−z): m = e × d = −x; flank normals (−sin45, 0, −sin45)·… i.e.
  // n₁ = sin45 (−z) + cos45 (−x), n₂ = sin45 (−z) + cos45 (+x). A point 0.1 mm on the −x side of
  // the blade plane, 1 mm above the edge: its nearest exit is flank n₁ (towards −x), at
  // s₁ = (−0.1, 0, 1) mm · n₁ = (0.1 − 1) sin45 mm, penetration 0.9 sin45 mm.
  const Eigen::Vector3d x(-0.1e-3, 0.0, 1e-3);
  const ToolContactPoint free = tool_contact(w, Eigen::Vector3d::Zero(), x);
  ASSERT_TRUE(free.inside);
  EXPECT_NEAR(free.penetration, 0.9e-3 * std::sin(std::numbers::pi / 4.0), 1e-15);
  EXPECT_LT(free.normal.x(), 0.0);
  // The same point on the crack face whose material lies towards +x may only leave towards +x:
  // through flank n₂, s₂ = (−0.1, 0, 1) mm · n₂ = (−0.1 − 1) sin45 mm, penetration 1.1 sin45 mm.
  const ToolContactPoint own = tool_contact(w, Eigen::Vector3d::Zero(), x, Eigen::Vector3d::UnitX());
  ASSERT_TRUE(own.inside);
  EXPECT_NEAR(own.penetration, 1.1e-3 * std::sin(std::numbers::pi / 4.0), 1e-15);
  EXPECT_NEAR((own.normal - std::sin(std::numbers::pi / 4.0) * Eigen::Vector3d(1, 0, -1)).norm(), 0.0, 1e-12);
  // A side does not make an outside point inside.
  EXPECT_FALSE(tool_contact(w, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -1e-4), Eigen::Vector3d::UnitX()).inside);
}

// The contact search's bound (rigid_tool.hpp, bounding_half_spaces): every point tool_contact
// finds inside lies strictly inside each of the six half-spaces, and no convex combination of
// points that outside_together rejects is inside the tool (checked against tool_contact itself,
// the second method, on random points around a sphere and a tilted wedge).
TEST(RigidTool, BoundingHalfSpacesHoldTheToolAndRejectOnlyOutsideHulls) {
  RigidToolShape sphere;
  sphere.radius = 2e-3;
  RigidToolShape wedge;
  wedge.kind = RigidToolShape::Kind::wedge;
  wedge.blade.edge_direction = Eigen::Vector3d(1, 1, 0).normalized();
  wedge.blade.cutting_direction = Eigen::Vector3d(1, -1, -2).normalized();
  wedge.blade.wedge_angle = 0.5;
  wedge.blade.thickness = 1.5e-3;
  wedge.blade.edge_length = 4e-3;
  validate(wedge);
  const Eigen::Vector3d c(1e-3, -2e-3, 0.5e-3);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-5e-3, 5e-3), unit(0.0, 1.0);
  auto point = [&] { return Eigen::Vector3d(c.x() + coordinate(random), c.y() + coordinate(random), c.z() + coordinate(random)); };
  for (const RigidToolShape& tool : {sphere, wedge}) {
    const ToolHalfSpaces h = bounding_half_spaces(tool);
    int inside = 0, rejected = 0;
    for (int k = 0; k < 20000; ++k) {
      const Eigen::Vector3d x = point();
      if (!tool_contact(tool, c, x).inside) continue;
      ++inside;
      for (std::size_t f = 0; f < h.normal.size(); ++f) EXPECT_LT((x - c).dot(h.normal[f]), h.offset[f]);
    }
    for (int k = 0; k < 20000; ++k) {
      // A small triangle (a boundary face's size) somewhere around the tool.
      const Eigen::Vector3d a = point();
      const std::array<Eigen::Vector3d, 3> t{a, a + 0.2 * (point() - c), a + 0.2 * (point() - c)};
      if (!outside_together(h, c, t)) continue;
      ++rejected;
      for (int q = 0; q < 10; ++q) {
        double l1 = unit(random), l2 = unit(random);
        if (l1 + l2 > 1.0) l1 = 1.0 - l1, l2 = 1.0 - l2;
        EXPECT_FALSE(tool_contact(tool, c, (1.0 - l1 - l2) * t[0] + l1 * t[1] + l2 * t[2]).inside);
      }
    }
    // Both checks saw cases (the sampling box holds the tool and much around it).
    EXPECT_GT(inside, 50);
    EXPECT_GT(rejected, 1000);
  }
}

TEST(ToolContact, ContactResultantBalancesTheSupportReaction) {
  const double L = 0.02, R = 4e-3;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d(-L / 2, -L / 2, 0), Eigen::Vector3d(L / 2, L / 2, L / 2), 4, 4, 2);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  RigidToolShape sphere;
  sphere.radius = R;
  p.tool = sphere;
  FiniteStrainSolver solver(p, SolverSettings{});
  for (double depth : {0.2e-3, 0.4e-3}) {
    const EquilibriumReport r = solver.solve({0.0, Eigen::Vector3d(0, 0, L / 2 + R - depth)});
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_GT(r.contact_points, 0);
    EXPECT_GT(r.tool_force.z(), 0.0); // the body pushes the tool back up
    EXPECT_LT((r.tool_force + r.support_reaction).norm(), 1e-8 * r.tool_force.norm());
  }
}

} // namespace
} // namespace kerf::reference
