#include "realtime/springs/cell_stiffness.hpp"

#include "meshes/lame_parameters.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

CellIdentification identify_cell_stiffness(double youngs_modulus, double poisson_ratio, double cell_size,
                                           bool volume_term) {
  if (!(youngs_modulus > 0.0) || !std::isfinite(youngs_modulus))
    throw std::invalid_argument("identify_cell_stiffness: Young's modulus must be > 0, got " + std::to_string(youngs_modulus));
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
    throw std::invalid_argument("identify_cell_stiffness: cell size must be > 0, got " + std::to_string(cell_size));
  if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
    throw std::invalid_argument("identify_cell_stiffness: Poisson ratio must be in (-1, 0.5), got " + std::to_string(poisson_ratio));
  const double E = youngs_modulus, nu = poisson_ratio, h = cell_size;
  CellIdentification id;
  // Material Lamé constants: μ = E / (2(1+ν)), λ = E ν / ((1+ν)(1−2ν)).
  const auto [mu, lambda] = lame_parameters(E, nu);
  double mu_springs = 0.0;
  if (volume_term) {
    if (nu < 0.25)
      throw std::invalid_argument("identify_cell_stiffness: the volume term represents ν >= 1/4 only (κ = λ − μ < 0 for ν = " +
                                  std::to_string(nu) + "); use springs alone");
    mu_springs = mu;
    id.stiffness.volume_modulus = lambda - mu;
    id.youngs_modulus = E;
    id.poisson_ratio = nu;
  } else {
    // Central springs: λ = μ (Cauchy), so ν = 1/4 and E = 5μ/2; E is matched.
    mu_springs = 2.0 * E / 5.0;
    id.youngs_modulus = E;
    id.poisson_ratio = 0.25;
  }
  // C44 = (2k₂ + 4k₃/3)/h = μ with k₂ = k₃ = k  ⇒  k = 3 μ h / 10; isotropy k₁ = k/2 + 2k/3 = 7k/6.
  const double k = 3.0 * mu_springs * h / 10.0;
  id.stiffness.face_diagonal = k;
  id.stiffness.body_diagonal = k;
  id.stiffness.edge = 7.0 * k / 6.0;
  // Bulk modulus K = λ + 2μ/3 of the network against the material's.
  const double lambda_net = mu_springs + id.stiffness.volume_modulus;
  id.bulk_modulus_error = (lambda_net + 2.0 * mu_springs / 3.0) / (lambda + 2.0 * mu / 3.0) - 1.0;
  return id;
}

Eigen::Matrix<double, 6, 6> cell_elasticity_tensor(const CellStiffness& s, double h) {
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  static constexpr int voigt[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) {
      const Eigen::Vector3d d((b & 1) - (a & 1), ((b >> 1) & 1) - ((a >> 1) & 1), ((b >> 2) & 1) - ((a >> 2) & 1));
      const int type = static_cast<int>(d.cwiseAbs().sum()); // 1 edge, 2 face diagonal, 3 body diagonal
      const double k = type == 1 ? s.edge : type == 2 ? s.face_diagonal : s.body_diagonal;
      const double l2 = d.squaredNorm() * h * h;
      const Eigen::Vector3d n = d.normalized();
      // C_ijkl += k l² n_i n_j n_k n_l / h³
      for (int I = 0; I < 6; ++I)
        for (int J = 0; J < 6; ++J)
          C(I, J) += k * l2 * n[voigt[I][0]] * n[voigt[I][1]] * n[voigt[J][0]] * n[voigt[J][1]] / (h * h * h);
    }
  for (int I = 0; I < 3; ++I)
    for (int J = 0; J < 3; ++J) C(I, J) += s.volume_modulus;
  return C;
}

} // namespace kerf
