#include "reference/material/neo_hookean.hpp"

#include "reference/material/finite_strain_error.hpp"

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

NeoHookean::NeoHookean(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
  if (!(mu > 0.0) || !(lambda + 2.0 * mu / 3.0 > 0.0) || !std::isfinite(mu) || !std::isfinite(lambda))
    throw std::invalid_argument("NeoHookean: need mu > 0 and bulk modulus lambda + 2 mu / 3 > 0, got mu = " +
                                std::to_string(mu) + " Pa, lambda = " + std::to_string(lambda) + " Pa");
}

double NeoHookean::energy(const Eigen::Matrix3d& F) const {
  const double J = checked_jacobian(F);
  const double lnJ = std::log(J);
  // ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²
  return 0.5 * m_mu * ((F.transpose() * F).trace() - 3.0) - m_mu * lnJ + 0.5 * m_lambda * lnJ * lnJ;
}

Eigen::Matrix3d NeoHookean::second_piola(const Eigen::Matrix3d& F) const {
  const double lnJ = std::log(checked_jacobian(F));
  const Eigen::Matrix3d Ci = (F.transpose() * F).inverse();
  // S = μ (I − C⁻¹) + λ ln J C⁻¹
  return m_mu * (Eigen::Matrix3d::Identity() - Ci) + m_lambda * lnJ * Ci;
}

void NeoHookean::second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const {
  const double lnJ = std::log(checked_jacobian(F));
  const Eigen::Matrix3d Ci = (F.transpose() * F).inverse();
  S = second_piola(F);
  // ℂ = λ C⁻¹ ⊗ C⁻¹ + 2 (μ − λ ln J) 𝕀_{C⁻¹}
  C4 = m_lambda * dyadic(Ci, Ci) + 2.0 * (m_mu - m_lambda * lnJ) * inverse_derivative_tensor(Ci);
}

} // namespace kerf::reference
