#pragma once
// FiniteStrainError: a deformation the reference cannot evaluate (an inverted or degenerate
// element, det F <= 0). The Newton solver catches it and cuts the load step back.

#include <Eigen/Core>

#include <stdexcept>
#include <string>

namespace kerf::reference {

/// Thrown when det F <= 0 or is not finite at a quadrature point.
class FiniteStrainError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// J = det F, checked: throws FiniteStrainError unless J > 0 and finite.
double checked_jacobian(const Eigen::Matrix3d& F);

} // namespace kerf::reference
