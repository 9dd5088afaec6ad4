#pragma once
// Compressible neo-Hookean law with an isochoric/volumetric split, exactly as in the deal.II code
// gallery program "Quasi-Static Finite-Strain Compressible Elasticity" (Pelteret & McBride 2016,
// doi:10.5281/zenodo.1228964, class Material_Compressible_Neo_Hook_One_Field):
//   ψ = c₁ (Ī₁ − 3) + κ/4 (J² − 1 − 2 ln J),   Ī₁ = J^(−2/3) tr C,
//   c₁ = μ/2,  κ = λ + 2μ/3 = 2μ(1+ν) / (3(1−2ν)).
// kerf uses it for the Cook's membrane verification against that program's published values.

#include "reference/material/hyperelastic_law.hpp"

namespace kerf::reference {

/// Decoupled compressible neo-Hookean solid (see file comment). μ, κ [Pa].
class DecoupledNeoHookean final : public HyperelasticLaw {
public:
  /// Throws std::invalid_argument unless μ > 0 and κ > 0.
  DecoupledNeoHookean(double mu, double kappa);
  DecoupledNeoHookean() = delete;
  [[nodiscard]] double energy(const Eigen::Matrix3d& F) const override;
  /// S = 2c₁ J^(−2/3) (I − I₁/3 C⁻¹) + κ/2 (J² − 1) C⁻¹;
  /// ℂ = 4c₁ J^(−2/3) [ I₁/3 𝕀_{C⁻¹} + I₁/9 C⁻¹⊗C⁻¹ − 1/3 (I⊗C⁻¹ + C⁻¹⊗I) ]
  ///     + κ J² C⁻¹⊗C⁻¹ − κ (J² − 1) 𝕀_{C⁻¹}
  /// (S = 2∂ψ/∂C with ∂J/∂C = J/2 C⁻¹, ∂C⁻¹/∂C = −𝕀_{C⁻¹}; Holzapfel 2000, §6.4–6.6).
  void second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const override;
  [[nodiscard]] Eigen::Matrix3d second_piola(const Eigen::Matrix3d& F) const override;

private:
  double m_mu;
  double m_kappa;
};

} // namespace kerf::reference
