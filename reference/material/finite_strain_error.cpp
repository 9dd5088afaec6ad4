#include "reference/material/finite_strain_error.hpp"

#include <Eigen/LU>

#include <cmath>

namespace kerf::reference {

double checked_jacobian(const Eigen::Matrix3d& F) {
  const double J = F.determinant();
  if (!(J > 0.0) || !std::isfinite(J))
    throw FiniteStrainError("finite strain: det F = " + std::to_string(J) + " (inverted or degenerate element)");
  return J;
}

} // namespace kerf::reference
