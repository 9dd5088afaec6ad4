#pragma once
// Compressible neo-Hookean law in the form of Bonet & Wood (2008), "Nonlinear Continuum
// Mechanics for Finite Element Analysis", 2nd ed., §6.4.3, eq. (6.27):
//   ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²,   I₁ = tr C,  J = det F.
// The law kerf's scenes use (scene `law = "neo-hookean"`); it reduces to linear elasticity with
// the same μ, λ at small strain.

#include "reference/material/hyperelastic_law.hpp"

namespace kerf::reference {

/// Bonet–Wood compressible neo-Hookean solid (see file comment). μ, λ [Pa].
class NeoHookean final : public HyperelasticLaw {
public:
  /// Throws std::invalid_argument unless μ > 0 and the bulk modulus λ + 2μ/3 > 0.
  NeoHookean(double mu, double lambda);
  NeoHookean() = delete;
  [[nodiscard]] double energy(const Eigen::Matrix3d& F) const override;
  /// S = μ (I − C⁻¹) + λ ln J C⁻¹;   ℂ = λ C⁻¹ ⊗ C⁻¹ + 2 (μ − λ ln J) 𝕀_{C⁻¹}
  /// (Bonet & Wood 2008, eqs. 6.28 and 6.40).
  void second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const override;
  [[nodiscard]] Eigen::Matrix3d second_piola(const Eigen::Matrix3d& F) const override;

private:
  double m_mu;
  double m_lambda;
};

} // namespace kerf::reference
