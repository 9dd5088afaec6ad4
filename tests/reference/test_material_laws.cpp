// The material laws' stress and tangent against central finite differences of their own energy
// and stress (an independent check of each derivative), and their small-strain limit against
// Hooke's law.

#include "reference/material/decoupled_neo_hookean.hpp"
#include "reference/material/finite_strain_error.hpp"
#include "reference/material/neo_hookean.hpp"
#include "reference/material/st_venant_kirchhoff.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <memory>
#include <random>
#include <vector>

namespace kerf::reference {
namespace {

std::vector<std::unique_ptr<HyperelasticLaw>> all_laws() {
  const LameParameters l = lame_parameters(3e6, 0.45);
  std::vector<std::unique_ptr<HyperelasticLaw>> laws;
  laws.push_back(std::make_unique<NeoHookean>(l.mu, l.lambda));
  laws.push_back(std::make_unique<DecoupledNeoHookean>(l.mu, l.lambda + 2.0 * l.mu / 3.0));
  laws.push_back(std::make_unique<StVenantKirchhoff>(l.mu, l.lambda));
  return laws;
}

std::vector<Eigen::Matrix3d> deformations() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  std::vector<Eigen::Matrix3d> out{Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.5, 0.8, 0.9).asDiagonal()};
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += d(rng);
    if (F.determinant() > 0.2) out.push_back(F);
  }
  return out;
}

TEST(MaterialLaws, FirstPiolaIsTheEnergyDerivative) {
  // P_iJ = ∂ψ/∂F_iJ, by central differences of ψ (step 1e-6, truncation O(1e-12)).
  for (const auto& law : all_laws())
    for (const Eigen::Matrix3d& F : deformations()) {
      const Eigen::Matrix3d P = law->stress_and_tangent(F).first_piola;
      const double h = 1e-6;
      for (int i = 0; i < 3; ++i)
        for (int J = 0; J < 3; ++J) {
          Eigen::Matrix3d Fp = F, Fm = F;
          Fp(i, J) += h;
          Fm(i, J) -= h;
          const double fd = (law->energy(Fp) - law->energy(Fm)) / (2.0 * h);
          EXPECT_NEAR(P(i, J), fd, 1e-6 * (std::abs(fd) + 3e6)) << "i=" << i << " J=" << J;
        }
    }
}

TEST(MaterialLaws, TangentIsTheStressDerivative) {
  // 𝔸_iJkL = ∂P_iJ/∂F_kL, by central differences of P.
  for (const auto& law : all_laws())
    for (const Eigen::Matrix3d& F : deformations()) {
      const Tensor4 A = law->stress_and_tangent(F).tangent;
      const double h = 1e-7;
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) {
          Eigen::Matrix3d Fp = F, Fm = F;
          Fp(k, L) += h;
          Fm(k, L) -= h;
          const Eigen::Matrix3d dP =
              (law->stress_and_tangent(Fp).first_piola - law->stress_and_tangent(Fm).first_piola) / (2.0 * h);
          for (int i = 0; i < 3; ++i)
            for (int J = 0; J < 3; ++J) EXPECT_NEAR(A(3 * i + J, 3 * k + L), dP(i, J), 1e-6 * 3e7);
        }
      // Hyperelastic: 𝔸 has major symmetry.
      EXPECT_LT((A - A.transpose()).cwiseAbs().maxCoeff(), 1e-8 * A.cwiseAbs().maxCoeff());
    }
}

TEST(MaterialLaws, SmallStrainLimitIsHookesLaw) {
  // At F = I every law's tangent is the isotropic Hooke tensor λ δ_iJ δ_kL + μ (δ_ik δ_JL + δ_iL δ_Jk),
  // and the reference configuration is stress-free.
  const double E = 3e6, nu = 0.45;
  const LameParameters l = lame_parameters(E, nu);
  for (const auto& law : all_laws()) {
    const StressTangent st = law->stress_and_tangent(Eigen::Matrix3d::Identity());
    EXPECT_LT(st.first_piola.norm(), 1e-9 * E);
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        for (int k = 0; k < 3; ++k)
          for (int L = 0; L < 3; ++L) {
            const double hooke = l.lambda * (i == J) * (k == L) + l.mu * ((i == k) * (J == L) + (i == L) * (J == k));
            EXPECT_NEAR(st.tangent(3 * i + J, 3 * k + L), hooke, 1e-9 * E);
          }
  }
}

TEST(MaterialLaws, InvertedDeformationIsRefused) {
  const LameParameters l = lame_parameters(1e6, 0.3);
  const NeoHookean law(l.mu, l.lambda);
  const Eigen::Matrix3d F = Eigen::Vector3d(1.0, 1.0, -0.5).asDiagonal();
  EXPECT_THROW((void)law.energy(F), FiniteStrainError);
  EXPECT_THROW((void)law.stress_and_tangent(F), FiniteStrainError);
}

TEST(MaterialLaws, BadParametersAreRefused) {
  EXPECT_THROW(lame_parameters(-1.0, 0.3), std::invalid_argument);
  EXPECT_THROW(lame_parameters(1e6, 0.5), std::invalid_argument);
  EXPECT_THROW(NeoHookean(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(DecoupledNeoHookean(1.0, 0.0), std::invalid_argument);
}

} // namespace
} // namespace kerf::reference
