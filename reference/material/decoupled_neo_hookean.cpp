#include "reference/material/decoupled_neo_hookean.hpp"

#include "reference/material/finite_strain_error.hpp"

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

DecoupledNeoHookean::DecoupledNeoHookean(double mu, double kappa) : m_mu(mu), m_kappa(kappa) {
  if (!(mu > 0.0) || !(kappa > 0.0) || !std::isfinite(mu) || !std::isfinite(kappa))
    throw std::invalid_argument("DecoupledNeoHookean: need mu > 0 and kappa > 0, got mu = " + std::to_string(mu) +
                                " Pa, kappa = " + std::to_string(kappa) + " Pa");
}

double DecoupledNeoHookean::energy(const Eigen::Matrix3d& F) const {
  const double J = checked_jacobian(F);
  const double I1_bar = std::pow(J, -2.0 / 3.0) * (F.transpose() * F).trace();
  // ψ = c₁ (Ī₁ − 3) + κ/4 (J² − 1 − 2 ln J), c₁ = μ/2
  return 0.5 * m_mu * (I1_bar - 3.0) + 0.25 * m_kappa * (J * J - 1.0 - 2.0 * std::log(J));
}

Eigen::Matrix3d DecoupledNeoHookean::second_piola(const Eigen::Matrix3d& F) const {
  const double J = checked_jacobian(F);
  const Eigen::Matrix3d C = F.transpose() * F;
  const Eigen::Matrix3d Ci = C.inverse();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double I1 = C.trace();
  const double Jm23 = std::pow(J, -2.0 / 3.0);
  const double c1 = 0.5 * m_mu;
  // S = 2c₁ J^(−2/3) (I − I₁/3 C⁻¹) + κ/2 (J² − 1) C⁻¹
  return 2.0 * c1 * Jm23 * (I - I1 / 3.0 * Ci) + 0.5 * m_kappa * (J * J - 1.0) * Ci;
}

void DecoupledNeoHookean::second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const {
  const double J = checked_jacobian(F);
  const Eigen::Matrix3d C = F.transpose() * F;
  const Eigen::Matrix3d Ci = C.inverse();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double I1 = C.trace();
  const double Jm23 = std::pow(J, -2.0 / 3.0);
  const double c1 = 0.5 * m_mu;
  S = second_piola(F);
  const Tensor4 Ic = inverse_derivative_tensor(Ci);
  const Tensor4 CiCi = dyadic(Ci, Ci);
  // ℂ_iso = 4c₁ J^(−2/3) [ I₁/3 𝕀 + I₁/9 C⁻¹⊗C⁻¹ − 1/3 (I⊗C⁻¹ + C⁻¹⊗I) ]
  C4 = 4.0 * c1 * Jm23 * (I1 / 3.0 * Ic + I1 / 9.0 * CiCi - (dyadic(I, Ci) + dyadic(Ci, I)) / 3.0);
  // ℂ_vol = κ J² C⁻¹⊗C⁻¹ − κ (J² − 1) 𝕀
  C4 += m_kappa * J * J * CiCi - m_kappa * (J * J - 1.0) * Ic;
}

} // namespace kerf::reference
