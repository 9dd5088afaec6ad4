#include "reference/material/st_venant_kirchhoff.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

StVenantKirchhoff::StVenantKirchhoff(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
  if (!(mu > 0.0) || !(lambda + 2.0 * mu / 3.0 > 0.0) || !std::isfinite(mu) || !std::isfinite(lambda))
    throw std::invalid_argument("StVenantKirchhoff: need mu > 0 and lambda + 2 mu / 3 > 0, got mu = " +
                                std::to_string(mu) + " Pa, lambda = " + std::to_string(lambda) + " Pa");
}

double StVenantKirchhoff::energy(const Eigen::Matrix3d& F) const {
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  // ψ = λ/2 (tr E)² + μ E:E
  return 0.5 * m_lambda * E.trace() * E.trace() + m_mu * E.cwiseProduct(E).sum();
}

Eigen::Matrix3d StVenantKirchhoff::second_piola(const Eigen::Matrix3d& F) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - I);
  // S = λ tr(E) I + 2μ E
  return m_lambda * E.trace() * I + 2.0 * m_mu * E;
}

void StVenantKirchhoff::second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  S = second_piola(F);
  // ℂ = λ I⊗I + 2μ 𝕀ˢ, 𝕀ˢ_IJKL = ½ (δ_IK δ_JL + δ_IL δ_JK) (= 𝕀_{C⁻¹} at C = I)
  C4 = m_lambda * dyadic(I, I) + 2.0 * m_mu * inverse_derivative_tensor(I);
}

} // namespace kerf::reference
