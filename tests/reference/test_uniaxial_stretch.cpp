// Uniaxial stretch of a neo-Hookean block with free lateral faces against the closed form.
// Bonet–Wood neo-Hookean (Bonet & Wood 2008, eq. 6.28): S = μ(I − C⁻¹) + λ ln J C⁻¹. With
// F = diag(λ₁, λ₂, λ₂) and S₂₂ = 0 the lateral stretch solves μ(λ₂² − 1) + λ ln(λ₁ λ₂²) = 0, and the
// nominal stress is P₁₁ = λ₁ S₁₁ = [μ(λ₁² − 1) + λ ln J] / λ₁ (derived here from eq. 6.28).

#include "reference/finite_strain_solver.hpp"
#include "reference/material/hyperelastic_law.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kerf::reference {
namespace {

// Lateral stretch λ₂ of the closed form, by Newton's method on μ(λ₂² − 1) + λ ln(λ₁ λ₂²) = 0.
double lateral_stretch(double mu, double lambda, double l1) {
  double l2 = 1.0;
  for (int k = 0; k < 50; ++k) {
    const double f = mu * (l2 * l2 - 1.0) + lambda * std::log(l1 * l2 * l2);
    const double df = 2.0 * mu * l2 + 2.0 * lambda / l2;
    l2 -= f / df;
  }
  return l2;
}

TEST(UniaxialStretch, NeoHookeanBlockMatchesTheClosedForm) {
  const double E = 1e6, nu = 0.3, L = 0.02, l1 = 1.5;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, L, L), 2, 2, 2);
  p.materials.push_back({"body", LawKind::neo_hookean, E, nu});
  // Symmetry planes slide; the x = L face is pulled to x = λ₁ L; y = L and z = L are free.
  for (const char* s : {"xmin", "ymin", "zmin"}) p.displacement_boundaries.push_back({s, DisplacementBoundary::Kind::sliding, {}, {}});
  DisplacementBoundary pull;
  pull.surface = "xmax";
  pull.kind = DisplacementBoundary::Kind::prescribed;
  pull.components = {true, false, false};
  pull.displacement = [&](const Eigen::Vector3d&, double load) -> Eigen::Vector3d { return {load * (l1 - 1.0) * L, 0, 0}; };
  p.displacement_boundaries.push_back(pull);
  FiniteStrainSolver solver(p, SolverSettings{});
  for (int step = 1; step <= 5; ++step) {
    const EquilibriumReport r = solver.solve({step / 5.0, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(r.converged) << r.failure;
    if (step < 5) continue;
    const LameParameters lame = lame_parameters(E, nu);
    const double l2 = lateral_stretch(lame.mu, lame.lambda, l1);
    const double J = l1 * l2 * l2;
    const double P11 = (lame.mu * (l1 * l1 - 1.0) + lame.lambda * std::log(J)) / l1;
    // The two x faces carry ±P₁₁ L² (their sum cancels): compare contraction and stress.
    EXPECT_NEAR(solver.displacement_at(Eigen::Vector3d(L, L, L))[1], (l2 - 1.0) * L, 1e-3 * std::abs(l2 - 1.0) * L);
    EXPECT_NEAR(solver.displacement_at(Eigen::Vector3d(L, L, L))[2], (l2 - 1.0) * L, 1e-3 * std::abs(l2 - 1.0) * L);
    for (const Eigen::Matrix3d& sigma : solver.quadrature_cauchy_stresses()) {
      // σ₁₁ = P₁₁ λ₁ / J (σ = J⁻¹ P Fᵀ), all other components zero.
      EXPECT_NEAR(sigma(0, 0), P11 * l1 / J, 1e-3 * P11 * l1 / J);
      EXPECT_LT((sigma - sigma(0, 0) * Eigen::Vector3d::UnitX() * Eigen::RowVector3d::UnitX()).cwiseAbs().maxCoeff(),
                1e-6 * P11);
    }
  }
}

} // namespace
} // namespace kerf::reference
