// The reference's numbers are versioned (reference/solver_version.hpp): a study's cache keys its
// profiles by reference::solver_version, so a change of the solver's output must come with a bump
// of that number. This test solves one small fixed problem -- a neo-Hookean and a St Venant-
// Kirchhoff block pressed by a rigid sphere (test_tool_contact.cpp's problem: material law, P1
// assembly, penalty contact, Newton) -- and compares its numbers with the values recorded for the
// current version. The tolerance, 1e-7 relative, is far above the Newton tolerance (1e-9 of the
// force scale), so a faster solver that converges to the same answer passes; a change of the
// answer fails with the message that says what to do.
//
// The recorded values are the solver's own output at the version named beside them (no
// independent closed form: the other reference tests check the solver against those).

#include "reference/finite_strain_solver.hpp"
#include "reference/solver_version.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace kerf::reference {
namespace {

struct Recorded {
  LawKind law;
  double depth;          ///< sphere indentation [m]
  double tool_force_z;   ///< contact resultant, body on tool [N]
  double contact_energy; ///< penalty energy [J]
  double top_centre_uz;  ///< displacement of the top face's centre [m]
};

// Recorded at solver_version 1; unchanged at 2, 3, 4 and 5 (2 changed the cohesive interface's Newton
// tangent, 3 the compliant grasp's layer, 4 the quadrature of quadratic tetrahedra, 5 the load
// path's loads between samples: none is part of this linear-element contact problem solved in one
// load).
constexpr int recorded_version = 5;
constexpr Recorded recorded[] = {
    {LawKind::neo_hookean, 0.2e-3, 0.016255006743663546, 3.6468403499959687e-08, -1.7448232701213008e-05},
    {LawKind::neo_hookean, 0.4e-3, 0.1835432044673154, 3.4721048657634074e-06, -0.00019462096659265718},
    {LawKind::st_venant_kirchhoff, 0.4e-3, 0.17676095380131837, 3.2725081859276789e-06, -0.00019636260260258014},
};

// The compliant grasp's case (below), recorded at version 3.
constexpr double recorded_foundation_force_z = -1.6601101808386631;
constexpr double recorded_foundation_top_uz = 0.00095331844521650069;

// The same contact problem on quadratic tetrahedra (below), recorded at version 4.
constexpr Recorded recorded_quadratic{LawKind::neo_hookean, 0.4e-3, 0.13381532556849468, 2.939563847190197e-06,
                                      -0.00038495166623036235};

constexpr double tolerance = 1e-7; // relative

void expect_unchanged(const char* what, double now, double then, const Recorded& r) {
  EXPECT_LE(std::abs(now - then), tolerance * std::abs(then))
      << "the reference's output changed: bump reference::solver_version and re-record (" << what << " at depth "
      << r.depth << " m, " << (r.law == LawKind::neo_hookean ? "neo-Hookean" : "St Venant-Kirchhoff")
      << "): now " << now << ", recorded " << then << " at version " << recorded_version;
}

// The block of side L (half as high) on its bonded base, a sphere of radius R above it.
constexpr double L = 0.02, R = 4e-3;
FiniteStrainProblem sphere_on_block(LawKind law) {
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d(-L / 2, -L / 2, 0), Eigen::Vector3d(L / 2, L / 2, L / 2), 4, 4, 2);
  p.materials.push_back({"body", law, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  RigidToolShape sphere;
  sphere.radius = R;
  p.tool = sphere;
  return p;
}

TEST(SolverVersion, TheReferencesOutputIsTheOneRecordedForItsVersion) {
  ASSERT_EQ(solver_version, recorded_version)
      << "solver_version was bumped: re-record the values of this test (printed below) for the new version";
  for (LawKind law : {LawKind::neo_hookean, LawKind::st_venant_kirchhoff}) {
    FiniteStrainSolver solver(sphere_on_block(law), SolverSettings{});
    for (const Recorded& r : recorded) {
      if (r.law != law) continue;
      const EquilibriumReport e = solver.solve({0.0, Eigen::Vector3d(0, 0, L / 2 + R - r.depth)});
      ASSERT_TRUE(e.converged) << e.failure;
      const double uz = solver.displacement_at(Eigen::Vector3d(0, 0, L / 2)).z();
      std::printf("[ recorded ] {%s, %.17g, %.17g, %.17g, %.17g},\n",
                  law == LawKind::neo_hookean ? "LawKind::neo_hookean" : "LawKind::st_venant_kirchhoff", r.depth,
                  e.tool_force.z(), e.contact_energy, uz);
      expect_unchanged("tool force", e.tool_force.z(), r.tool_force_z, r);
      expect_unchanged("contact energy", e.contact_energy, r.contact_energy, r);
      expect_unchanged("top-centre displacement", uz, r.top_centre_uz, r);
    }
  }
}

// The compliant grasp (ElasticFoundation with the tapered disc's profile, as reference_run builds
// it for a scene's grasp_stiffness): the same block's top centre pulled up through the layer.
TEST(SolverVersion, TheCompliantGraspsOutputIsTheOneRecordedForItsVersion) {
  ASSERT_EQ(solver_version, recorded_version)
      << "solver_version was bumped: re-record the values of this test (printed below) for the new version";
  const double a = 6e-3, k = 1e8, lift = 1e-3;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d(-L / 2, -L / 2, 0), Eigen::Vector3d(L / 2, L / 2, L / 2), 4, 4, 2);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.foundations.push_back({"zmax", k, [&](const Eigen::Vector3d&, double load) { return Eigen::Vector3d(0, 0, load * lift); },
                           ElasticFoundation::tapered_disc(Eigen::Vector3d(0, 0, L / 2), a)});
  FiniteStrainSolver solver(p, SolverSettings{});
  const EquilibriumReport e = solver.solve({1.0, Eigen::Vector3d::Zero()});
  ASSERT_TRUE(e.converged) << e.failure;
  ASSERT_EQ(e.foundation_forces.size(), 1u);
  const double fz = e.foundation_forces[0].z(), uz = solver.displacement_at(Eigen::Vector3d(0, 0, L / 2)).z();
  std::printf("[ recorded ] foundation force z %.17g, top-centre u_z %.17g\n", fz, uz);
  const Recorded r{LawKind::neo_hookean, lift, 0.0, 0.0, 0.0};
  expect_unchanged("foundation force", fz, recorded_foundation_force_z, r);
  expect_unchanged("top-centre displacement", uz, recorded_foundation_top_uz, r);
}

// The sphere's indentation on quadratic tetrahedra (the element, its quadrature and the boundary
// faces' contact search of degree 2).
TEST(SolverVersion, TheQuadraticElementsOutputIsTheOneRecordedForItsVersion) {
  ASSERT_EQ(solver_version, recorded_version)
      << "solver_version was bumped: re-record the values of this test (printed below) for the new version";
  SolverSettings settings;
  settings.degree = 2;
  FiniteStrainSolver solver(sphere_on_block(LawKind::neo_hookean), settings);
  const Recorded& r = recorded_quadratic;
  const EquilibriumReport e = solver.solve({0.0, Eigen::Vector3d(0, 0, L / 2 + R - r.depth)});
  ASSERT_TRUE(e.converged) << e.failure;
  const double uz = solver.displacement_at(Eigen::Vector3d(0, 0, L / 2)).z();
  std::printf("[ recorded ] quadratic: {LawKind::neo_hookean, %.17g, %.17g, %.17g, %.17g}\n", r.depth, e.tool_force.z(),
              e.contact_energy, uz);
  expect_unchanged("tool force (P2)", e.tool_force.z(), r.tool_force_z, r);
  expect_unchanged("contact energy (P2)", e.contact_energy, r.contact_energy, r);
  expect_unchanged("top-centre displacement (P2)", uz, r.top_centre_uz, r);
}

} // namespace
} // namespace kerf::reference
