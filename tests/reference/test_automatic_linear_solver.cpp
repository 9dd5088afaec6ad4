// The automatic linear solver of the finite-strain reference (SolverSettings::linear_solver =
// automatic): its choice between the direct factorisation and PETSc's CG + GAMG, checked on the
// affine patch (tests/reference/reference_test_meshes.hpp, affine_problem), whose exact solution
// is u = G X + b. Its own executable: the iterative branch initialises PETSc and so Open MPI,
// whose dlclose'd components leak at exit out of reach of a suppression (tests/CMakeLists.txt,
// KERF_PETSC_TEST_ENVIRONMENT).

#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace kerf::reference {
namespace {

// The automatic linear solver above direct_dof_limit: direct while CHOLMOD's predicted factor fits
// direct_factor_limit, iterative when it does not; either reproduces the affine field (the direct
// solver to round-off, CG to its 1e-10 relative residual).
TEST(AutomaticLinearSolver, DirectWhileThePredictedFactorFits) {
  const TetMesh mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.03, 0.02, 0.02), 3, 3, 3);
  Eigen::Matrix3d G;
  G << 0.05, 0.01, 0.0, 0.0, -0.02, 0.01, 0.01, 0.0, 0.03;
  const Eigen::Vector3d b(1e-4, 0.0, -2e-4);
  const Eigen::Vector3d X(0.01, 0.02 / 3.0, 0.02 / 3.0); // an interior node
  SolverSettings settings;
  settings.direct_dof_limit = 0;
  for (const double limit : {1e8, 1.0}) {
    settings.direct_factor_limit = limit;
    FiniteStrainSolver solver(test::affine_problem(mesh, G, b, LawKind::neo_hookean, 1e6, 0.3), settings);
    EXPECT_EQ(solver.linear_solver_name(), limit > 1.0 ? "cholmod/umfpack" : "petsc-cg-gamg");
    // The record says why: the DOFs above the limit and the predicted factor against its limit.
    EXPECT_NE(solver.linear_solver_reason().find(std::string(limit > 1.0 ? "direct: " : "iterative: ") +
                                                 std::to_string(solver.dof_count()) + " DOFs > direct_dof_limit 0; predicted Cholesky factor"),
              std::string::npos)
        << solver.linear_solver_reason();
    const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_LT((solver.displacement_at(X) - (G * X + b)).norm(), 1e-9 * (G * X + b).norm()) << "factor limit " << limit;
  }
  settings.direct_factor_limit = -1.0;
  EXPECT_THROW(FiniteStrainSolver(test::affine_problem(mesh, G, b, LawKind::neo_hookean, 1e6, 0.3), settings), std::invalid_argument);
}

} // namespace
} // namespace kerf::reference
