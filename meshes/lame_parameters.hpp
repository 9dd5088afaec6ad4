#pragma once
// The isotropic elastic constants every model and the reference share: Lamé's parameters from
// Young's modulus and Poisson's ratio (e.g. Bonet & Wood 2008, §6.4):
//   μ = E / (2(1+ν)),   λ = E ν / ((1+ν)(1−2ν)).

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

struct LameParameters {
  double mu = 0.0;     ///< shear modulus μ [Pa]
  double lambda = 0.0; ///< first Lamé parameter λ [Pa]
};

/// Lamé's parameters of Young's modulus E [Pa] > 0 (finite) and Poisson's ratio ν in (-1, 0.5).
/// Throws std::invalid_argument outside those ranges.
inline LameParameters lame_parameters(double youngs_modulus, double poisson_ratio) {
  const double E = youngs_modulus, nu = poisson_ratio;
  if (!(E > 0.0) || !std::isfinite(E))
    throw std::invalid_argument("lame_parameters: Young's modulus must be positive and finite, got " + std::to_string(E));
  if (!(nu > -1.0 && nu < 0.5))
    throw std::invalid_argument("lame_parameters: Poisson's ratio must lie in (-1, 0.5), got " + std::to_string(nu));
  return {E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

} // namespace kerf
