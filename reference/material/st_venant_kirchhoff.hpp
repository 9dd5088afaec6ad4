#pragma once
// St Venant–Kirchhoff law (Holzapfel 2000, eq. 6.151; Bonet & Wood 2008, eq. 6.11):
//   ψ = λ/2 (tr E)² + μ E:E,   E = ½ (C − I).
// Linear elasticity written in Green–Lagrange strain: exact for rigid rotations, but it softens
// and finally loses stability in compression — where "linear-ish" fast models part from a
// neo-Hookean body.

#include "reference/material/hyperelastic_law.hpp"

namespace kerf::reference {

/// St Venant–Kirchhoff solid. μ, λ [Pa].
class StVenantKirchhoff final : public HyperelasticLaw {
public:
  /// Throws std::invalid_argument unless μ > 0 and λ + 2μ/3 > 0.
  StVenantKirchhoff(double mu, double lambda);
  StVenantKirchhoff() = delete;
  [[nodiscard]] double energy(const Eigen::Matrix3d& F) const override;
  /// S = λ tr(E) I + 2μ E;   ℂ = λ I⊗I + 2μ 𝕀ˢ (𝕀ˢ the symmetric fourth-order identity).
  void second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const override;
  [[nodiscard]] Eigen::Matrix3d second_piola(const Eigen::Matrix3d& F) const override;

private:
  double m_mu;
  double m_lambda;
};

} // namespace kerf::reference
