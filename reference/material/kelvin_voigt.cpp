#include "reference/material/kelvin_voigt.hpp"

#include "meshes/lame_parameters.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

KelvinVoigtDamping kelvin_voigt_damping(double E, double nu, double eta) {
  if (!(eta >= 0.0) || !std::isfinite(eta))
    throw std::invalid_argument("Kelvin-Voigt damping: the viscosity eta must be >= 0 Pa s, got " + std::to_string(eta));
  if (!(E > 0.0) || !(nu > -1.0 && nu < 0.5))
    throw std::invalid_argument("Kelvin-Voigt damping: needs E > 0 and nu in (-1, 0.5), got E = " + std::to_string(E) +
                                " Pa, nu = " + std::to_string(nu));
  KelvinVoigtDamping d;
  d.retardation_time = eta / E; // τ = η / E
  const LameParameters lame = lame_parameters(E, nu);
  d.lambda = lame.lambda;
  d.mu = lame.mu;
  return d;
}

namespace {

/// ℂ₀ : A = λ tr(A) I + 2μ A for a symmetric A.
Eigen::Matrix3d small_strain_elasticity(const KelvinVoigtDamping& d, const Eigen::Matrix3d& A) {
  return d.lambda * A.trace() * Eigen::Matrix3d::Identity() + 2.0 * d.mu * A;
}

Eigen::Matrix3d sym(const Eigen::Matrix3d& A) { return 0.5 * (A + A.transpose()); }

} // namespace

StressTangent kelvin_voigt_stress(const KelvinVoigtDamping& d, const Eigen::Matrix3d& F, const Eigen::Matrix3d& F_rate,
                                  double c) {
  StressTangent out;
  if (d.retardation_time == 0.0) return out;
  const double tau = d.retardation_time;
  // Ė = sym(Fᵀ Ḟ), S_v = τ ℂ₀ : Ė, P_v = F S_v
  const Eigen::Matrix3d E_rate = sym(F.transpose() * F_rate);
  const Eigen::Matrix3d S_v = tau * small_strain_elasticity(d, E_rate);
  out.first_piola = F * S_v;
  // δP_v = δF S_v + F τ ℂ₀ : (sym(δFᵀ Ḟ) + c sym(Fᵀ δF)), column (3k+L) for δF = e_k ⊗ e_L.
  for (int k = 0; k < 3; ++k)
    for (int L = 0; L < 3; ++L) {
      Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
      dF(k, L) = 1.0;
      const Eigen::Matrix3d dE_rate = sym(dF.transpose() * F_rate) + c * sym(F.transpose() * dF);
      const Eigen::Matrix3d dP = dF * S_v + F * (tau * small_strain_elasticity(d, dE_rate));
      for (int i = 0; i < 3; ++i)
        for (int J = 0; J < 3; ++J) out.tangent(3 * i + J, 3 * k + L) = dP(i, J);
    }
  return out;
}

double kelvin_voigt_dissipation_rate(const KelvinVoigtDamping& d, const Eigen::Matrix3d& F, const Eigen::Matrix3d& F_rate) {
  const Eigen::Matrix3d E_rate = sym(F.transpose() * F_rate);
  // S_v : Ė = τ (λ tr(Ė)² + 2μ Ė:Ė)
  return d.retardation_time * (d.lambda * E_rate.trace() * E_rate.trace() + 2.0 * d.mu * E_rate.squaredNorm());
}

} // namespace kerf::reference
