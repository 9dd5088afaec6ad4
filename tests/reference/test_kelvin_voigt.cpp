// The Kelvin–Voigt viscous stress of the dynamic step (reference/material/kelvin_voigt.hpp)
// against independent values:
//   small strain   at F = I it is τ (λ tr(ε̇) I + 2μ ε̇) with ε̇ = sym(Ḟ) (the linear Kelvin–Voigt
//                  solid, docs/spring-network.md "Damping");
//   rigid spin     a rate Ḟ = W F with W skew is a rigid rotation rate: Ė = 0, no stress;
//   dissipation    S_v : Ė >= 0, and equal to 2φ = τ Ė:ℂ₀:Ė;
//   tangent        equal to central differences of P_v along F → F + s dF, Ḟ → Ḟ + c s dF.

#include "reference/material/kelvin_voigt.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace kerf::reference {
namespace {

Eigen::Matrix3d random_matrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = u(rng);
  return m;
}

TEST(KelvinVoigt, SmallStrainLimitIsTheLinearSolid) {
  const KelvinVoigtDamping d = kelvin_voigt_damping(2e6, 0.3, 50.0); // τ = 25 µs
  std::mt19937 rng(1);
  const Eigen::Matrix3d F_rate = random_matrix(rng, 3.0);
  const Eigen::Matrix3d eps_rate = 0.5 * (F_rate + F_rate.transpose());
  const double lambda = 2e6 * 0.3 / (1.3 * 0.4), mu = 2e6 / 2.6;
  const Eigen::Matrix3d expected = 25e-6 * (lambda * eps_rate.trace() * Eigen::Matrix3d::Identity() + 2.0 * mu * eps_rate);
  const Eigen::Matrix3d P = kelvin_voigt_stress(d, Eigen::Matrix3d::Identity(), F_rate, 0.0).first_piola;
  EXPECT_LT((P - expected).norm(), 1e-12 * expected.norm());
}

TEST(KelvinVoigt, RigidSpinCarriesNoStress) {
  const KelvinVoigtDamping d = kelvin_voigt_damping(1e6, 0.45, 10.0);
  std::mt19937 rng(2);
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + random_matrix(rng, 0.3);
  const Eigen::Matrix3d A = random_matrix(rng, 5.0), W = 0.5 * (A - A.transpose());
  const Eigen::Matrix3d P = kelvin_voigt_stress(d, F, W * F, 0.0).first_piola;
  EXPECT_LT(P.norm(), 1e-12 * d.retardation_time * d.mu * 5.0);
  EXPECT_NEAR(kelvin_voigt_dissipation_rate(d, F, W * F), 0.0, 1e-12 * d.retardation_time * d.mu);
}

TEST(KelvinVoigt, DissipationIsNonNegative) {
  const KelvinVoigtDamping d = kelvin_voigt_damping(1e6, 0.45, 10.0);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + random_matrix(rng, 0.4);
    const Eigen::Matrix3d F_rate = random_matrix(rng, 10.0);
    const Eigen::Matrix3d E_rate = 0.5 * (F.transpose() * F_rate + F_rate.transpose() * F);
    // P_v : Ḟ = S_v : Ė (the power of P_v on Ḟ equals that of S_v on Ė, S_v symmetric)
    const double power = kelvin_voigt_stress(d, F, F_rate, 0.0).first_piola.cwiseProduct(F_rate).sum();
    const double rate = kelvin_voigt_dissipation_rate(d, F, F_rate);
    EXPECT_GE(rate, 0.0);
    EXPECT_NEAR(power, rate, 1e-10 * (std::abs(rate) + d.retardation_time * d.mu * E_rate.squaredNorm()));
  }
}

TEST(KelvinVoigt, TangentMatchesCentralDifferences) {
  const KelvinVoigtDamping d = kelvin_voigt_damping(1e6, 0.45, 10.0);
  const double c = 2.0 / 1e-3; // γ/(βh) for h = 1 ms
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + random_matrix(rng, 0.3);
    const Eigen::Matrix3d F_rate = random_matrix(rng, 20.0);
    const Tensor4 A = kelvin_voigt_stress(d, F, F_rate, c).tangent;
    const double s = 1e-6;
    for (int kL = 0; kL < 9; ++kL) {
      Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
      dF(kL / 3, kL % 3) = 1.0;
      const Eigen::Matrix3d P_plus = kelvin_voigt_stress(d, F + s * dF, F_rate + c * s * dF, c).first_piola;
      const Eigen::Matrix3d P_minus = kelvin_voigt_stress(d, F - s * dF, F_rate - c * s * dF, c).first_piola;
      const Eigen::Matrix3d fd = (P_plus - P_minus) / (2.0 * s);
      for (int iJ = 0; iJ < 9; ++iJ) EXPECT_NEAR(A(iJ, kL), fd(iJ / 3, iJ % 3), 1e-6 * A.norm()) << "trial " << trial;
    }
  }
}

TEST(KelvinVoigt, RefusesANegativeViscosity) {
  EXPECT_THROW((void)kelvin_voigt_damping(1e6, 0.3, -1.0), std::invalid_argument);
  EXPECT_EQ(kelvin_voigt_damping(1e6, 0.3, 0.0).retardation_time, 0.0);
}

} // namespace
} // namespace kerf::reference
