// The iterative solver of the reference (reference/tangent_solver.hpp: PETSc CG + GAMG) on the
// stiffness of a slender cantilever, linear and quadratic tetrahedra, Poisson's ratio 0.3 to 0.49.
// Second method: the direct solver (CHOLMOD's Cholesky, the same TangentSolver in Kind::direct)
// on the same matrix and load; CG stops at a true residual of 1e-10 |b|, so the two solutions
// agree to ~1e-8 of the solution's norm (the condition number of these matrices times 1e-10 is
// below 1e2).
//
// What the test shows: smoothed-aggregation AMG needs the near null space of the operator, the
// six rigid-body modes of elasticity (Vaněk, Mandel & Brezina 1996, "Algebraic multigrid by
// smoothed aggregation for second and fourth order elliptic problems", Computing 56, §3; PETSc's
// MatNullSpaceCreateRigidBody). Given only the three translations (GAMG's default for block size
// 3), its coarse spaces cannot represent the bending of the cantilever and CG needs many times the
// iterations; with the rotations it converges in a few tens, and stays there as ν -> 0.49.

#include "reference/tangent_solver.hpp"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <ostream>
#include <stdexcept>

namespace kerf::reference {
namespace {

/// K u = b of small-strain elasticity (Hooke: σ = λ tr(ε) I + 2μ ε, the finite-strain tangent of
/// every law of reference/material/ at u = 0) on an 8 × 1 × 1 cantilever of n_x × 1 × 1 cubes each
/// split into tetrahedra, clamped at x = 0, loaded by a uniform downward body force.
struct Cantilever {
  dealii::Triangulation<3> tria;
  dealii::FESystem<3> fe;
  dealii::DoFHandler<3> dof;
  dealii::SparsityPattern pattern;
  dealii::SparseMatrix<double> K;
  dealii::Vector<double> b;
  std::vector<dealii::Point<3>> support;

  Cantilever(unsigned degree, double nu) : fe(dealii::FE_SimplexP<3>(degree), 3) {
    dealii::Triangulation<3> hexes;
    dealii::GridGenerator::subdivided_hyper_rectangle(hexes, {16, 2, 2}, dealii::Point<3>(), dealii::Point<3>(8.0, 1.0, 1.0));
    dealii::GridGenerator::convert_hypercube_to_simplex_mesh(hexes, tria);
    dof.reinit(tria);
    dof.distribute_dofs(fe);
    const dealii::MappingFE<3> mapping(dealii::FE_SimplexP<3>(1));
    support.resize(dof.n_dofs());
    dealii::DoFTools::map_dofs_to_support_points(mapping, dof, support);

    dealii::AffineConstraints<double> clamp;
    for (dealii::types::global_dof_index i = 0; i < dof.n_dofs(); ++i)
      if (support[i][0] < 1e-12) clamp.add_line(i);
    clamp.close();
    dealii::DynamicSparsityPattern dsp(dof.n_dofs());
    dealii::DoFTools::make_sparsity_pattern(dof, dsp, clamp, false);
    pattern.copy_from(dsp);
    K.reinit(pattern);
    b.reinit(dof.n_dofs());

    const double E = 1.0, lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
    const dealii::QGaussSimplex<3> quadrature(degree + 1);
    dealii::FEValues<3> fv(mapping, fe, quadrature, dealii::update_gradients | dealii::update_values | dealii::update_JxW_values);
    const dealii::FEValuesExtractors::Vector u(0);
    const unsigned n = fe.n_dofs_per_cell();
    dealii::FullMatrix<double> cell_K(n, n);
    dealii::Vector<double> cell_b(n);
    std::vector<dealii::types::global_dof_index> local(n);
    for (const auto& cell : dof.active_cell_iterators()) {
      fv.reinit(cell);
      cell_K = 0.0;
      cell_b = 0.0;
      for (unsigned q = 0; q < quadrature.size(); ++q)
        for (unsigned i = 0; i < n; ++i) {
          const auto eps_i = fv[u].symmetric_gradient(i, q);
          for (unsigned j = 0; j < n; ++j) {
            const auto eps_j = dealii::SymmetricTensor<2, 3>(fv[u].symmetric_gradient(j, q));
            cell_K(i, j) += (lambda * dealii::trace(eps_i) * dealii::trace(eps_j) + 2.0 * mu * (eps_i * eps_j)) * fv.JxW(q);
          }
          cell_b(i) += -1e-3 * fv[u].value(i, q)[2] * fv.JxW(q); // body force (0, 0, −1e-3)
        }
      cell->get_dof_indices(local);
      clamp.distribute_local_to_global(cell_K, cell_b, local, K, b);
    }
  }
};

struct Solution {
  dealii::Vector<double> x;
  int iterations = -1; ///< -1: did not converge
};

Solution solve(const Cantilever& c, TangentSolver::Kind kind, bool rigid_body_modes) {
  IterativeSettings settings;
  settings.rigid_body_modes = rigid_body_modes;
  settings.max_iterations = 1000;
  TangentSolver solver(kind, c.support, 1e-10, false, true, settings);
  Solution s;
  s.x.reinit(c.b.size());
  try {
    s.iterations = solver.solve(c.K, s.x, c.b);
  } catch (const std::runtime_error&) {
    s.iterations = -1;
  }
  return s;
}

struct Case {
  unsigned degree;
  double nu;
};
void PrintTo(const Case& c, std::ostream* os) { *os << "P" << c.degree << ", nu = " << c.nu; }

class GamgNearNullSpace : public ::testing::TestWithParam<Case> {};

TEST_P(GamgNearNullSpace, RigidBodyModesMakeCgConvergeInFewIterations) {
  const Case p = GetParam();
  const Cantilever c(p.degree, p.nu);
  const Solution direct = solve(c, TangentSolver::Kind::direct, true);
  const Solution with = solve(c, TangentSolver::Kind::iterative, true);
  const Solution without = solve(c, TangentSolver::Kind::iterative, false);
  std::printf("P%u, nu = %.2f, %u DOFs: CG + GAMG %d iterations with the rigid-body modes, %d without (-1: not in 1000)\n",
              p.degree, p.nu, c.dof.n_dofs(), with.iterations, without.iterations);
  ASSERT_GE(with.iterations, 0) << "CG + GAMG with the rigid-body modes did not converge";
  dealii::Vector<double> difference = with.x;
  difference -= direct.x;
  EXPECT_LT(difference.l2_norm(), 1e-7 * direct.x.l2_norm());
  // Without the rotations: at least twice the iterations (measured 2.4–3.3 times), or no
  // convergence in 1000.
  EXPECT_TRUE(without.iterations < 0 || without.iterations >= 2 * with.iterations)
      << with.iterations << " iterations with the modes, " << without.iterations << " without";
}

INSTANTIATE_TEST_SUITE_P(DegreesAndPoissonRatios, GamgNearNullSpace,
                         ::testing::Values(Case{1, 0.3}, Case{1, 0.45}, Case{1, 0.49}, Case{2, 0.3}, Case{2, 0.45},
                                           Case{2, 0.49}),
                         [](const auto& info) {
                           return "P" + std::to_string(info.param.degree) + "_nu" +
                                  std::to_string(static_cast<int>(info.param.nu * 100 + 0.5));
                         });

// An indefinite system (the cantilever's K shifted by −1.5 λ_min I: its lowest bending modes get
// negative eigenvalues, as a finite-strain tangent far from equilibrium can): CG meets it (p·Kp <= 0
// or an indefinite preconditioner) and hands the system to GMRES with the same GAMG, which solves
// it; second method: UMFPACK's LU (the direct solver, Cholesky failing) on the same system.
TEST(GamgNearNullSpace, AnIndefiniteSystemGoesFromCgToGmres) {
  Cantilever c(1, 0.3);
  // λ_min by inverse iteration with the direct solver (K is SPD before the shift).
  TangentSolver direct(TangentSolver::Kind::direct, c.support, 1e-10);
  dealii::Vector<double> v(c.b.size()), w(c.b.size());
  v = 1.0;
  double lambda = 0.0;
  for (int k = 0; k < 60; ++k) {
    v /= v.l2_norm();
    direct.solve(c.K, w, v);
    lambda = 1.0 / (v * w);
    v = w;
  }
  for (dealii::types::global_dof_index i = 0; i < c.b.size(); ++i)
    if (c.support[i][0] > 1e-12) c.K.add(i, i, -1.5 * lambda); // free DOFs only
  const Solution lu = solve(c, TangentSolver::Kind::direct, true);
  TangentSolver iterative(TangentSolver::Kind::iterative, c.support, 1e-10);
  dealii::Vector<double> x(c.b.size());
  iterative.solve(c.K, x, c.b);
  EXPECT_EQ(iterative.iterative_counters().indefinite_to_gmres, 1);
  x -= lu.x;
  EXPECT_LT(x.l2_norm(), 1e-7 * lu.x.l2_norm());
}

// Chosen automatically (the predicted factor too large for the direct solver), the iterative
// solver falls back to the direct one on a system it cannot solve — here because it may take only
// two iterations — says so, and stays direct; without the fall-back it throws.
TEST(GamgNearNullSpace, TheAutomaticChoiceFallsBackToTheDirectSolver) {
  const Cantilever c(1, 0.3);
  IterativeSettings two;
  two.max_iterations = 2;
  TangentSolver strict(TangentSolver::Kind::iterative, c.support, 1e-10, false, true, two);
  dealii::Vector<double> x(c.b.size());
  EXPECT_THROW(strict.solve(c.K, x, c.b), std::runtime_error);
  TangentSolver automatic(TangentSolver::Kind::iterative, c.support, 1e-10, false, true, two);
  automatic.set_choice_reason("iterative: chosen by the test");
  automatic.fall_back_to_direct_on_failure(true);
  EXPECT_EQ(automatic.solve(c.K, x, c.b), 0);
  EXPECT_EQ(automatic.kind(), TangentSolver::Kind::direct);
  EXPECT_NE(automatic.choice_reason().find("then direct: PETSc CG + GAMG did not converge"), std::string::npos)
      << automatic.choice_reason();
  const Solution reference = solve(c, TangentSolver::Kind::direct, true);
  x -= reference.x;
  EXPECT_LT(x.l2_norm(), 1e-12 * reference.x.l2_norm());
}

} // namespace
} // namespace kerf::reference
