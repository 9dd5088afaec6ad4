// The cohesive interface of the finite-strain reference (Reference II) against closed forms: a bar
// pulled apart across a cohesive plane — the peak force is σ_c A, the dissipation after complete
// separation is J_c A (the definition of J_c as the area under the law), and the external work
// equals strain energy + interface energy + dissipation at every step.

#include "meshes/crack_split.hpp"
#include "reference/finite_strain_solver.hpp"
#include "reference/load_path.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include "tests/reference/proportional_load.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kerf::reference {
namespace {

using test::add_interior_face_group;
using test::named_box;

TEST(CohesiveInterface, BarPulledApartDissipatesToughnessTimesArea) {
  // Bar 4 x 2 x 2 mm, cohesive plane x = 2 mm. E = 10 MPa, ν = 0 (uniaxial), σ_c = 0.1 MPa,
  // J_c = 50 J/m²: δ_f = 2 J_c/σ_c = 1 mm. The bulk stiffness per area E/L = 2.5e9 Pa/m exceeds the
  // softening slope σ_c/(δ_f − δ_0) ≈ 1e8 Pa/m, so the separation is stable under displacement control.
  const double L = 4e-3, W = 2e-3;
  TetMesh mesh = named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, W, W), 4, 2, 2);
  add_interior_face_group(mesh, "cut_plane", [&](const Eigen::Vector3d& x) { return std::abs(x.x() - L / 2) < 1e-12; });
  const CrackSplit split = split_along_surface(mesh, "cut_plane");

  FiniteStrainProblem problem;
  problem.mesh = split.mesh;
  problem.materials = {{"body", LawKind::neo_hookean, 10e6, 0.0}};
  problem.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {true, true, true}});
  const double stretch = 1.2e-3; // past δ_f plus the bulk's own stretch
  DisplacementBoundary pull{"xmax", DisplacementBoundary::Kind::prescribed,
                            [&](const Eigen::Vector3d&, double load) { return Eigen::Vector3d(load * stretch, 0, 0); },
                            {true, true, true}}; // held in y and z too: once separated, the right part has no other support
  problem.displacement_boundaries.push_back(pull);
  CohesiveInterfaceSpec spec{"cut_plane+", "cut_plane-", {}};
  spec.law.cohesive_strength = 0.1e6;
  spec.law.fracture_toughness = 50.0;
  problem.cohesive = spec;
  SolverSettings settings;
  settings.degree = 1;
  FiniteStrainSolver solver(problem, settings);
  ASSERT_GT(solver.cohesive_point_count(), 0u);

  LoadPath path(solver, LoadState{});
  const int steps = 240;
  double work = 0.0, previous_force = 0.0, peak = 0.0;
  const double area = W * W;
  for (int k = 1; k <= steps; ++k) {
    const LoadStepReport step = path.advance(test::proportional_target(k, steps));
    ASSERT_TRUE(step.converged);
    // The pull's force on the body: minus the reaction (body on the pulled face).
    const double force = -step.equilibrium.boundary_reactions[1].force.x();
    work += 0.5 * (force + previous_force) * stretch / steps;        // trapezoid rule ∫ F dδ
    previous_force = force;
    peak = std::max(peak, force);
    const CohesiveSummary& c = step.equilibrium.cohesive;
    const double balance = solver.strain_energy() + c.stored_energy + c.dissipated_energy + c.viscous_dissipation;
    // Energy balance: W_ext = U + U_interface + D, to the trapezoid rule's error (<1% of J_c A).
    EXPECT_NEAR(work, balance, 0.01 * spec.law.fracture_toughness * area) << "step " << k;
  }
  // Peak nominal force σ_c A (the law acts per reference area); the uniform state makes it exact
  // up to the load step's resolution of the peak.
  EXPECT_NEAR(peak, spec.law.cohesive_strength * area, 0.01 * spec.law.cohesive_strength * area);
  // After separation: no force, every point failed, dissipation J_c A.
  EXPECT_NEAR(previous_force, 0.0, 1e-9 * spec.law.cohesive_strength * area);
  const LoadStepReport last = path.advance(LoadTarget{LoadState{1.0, Eigen::Vector3d::Zero(), 1.0 + 1.0 / steps}, 0, 0.0});
  EXPECT_NEAR(last.equilibrium.cohesive.failed_area, area, 1e-12 * area);
  EXPECT_NEAR(last.equilibrium.cohesive.dissipated_energy, spec.law.fracture_toughness * area, 0.02 * spec.law.fracture_toughness * area);
}

} // namespace
} // namespace kerf::reference
