#include "viewer/von_mises.hpp"

#include "meshes/lame_parameters.hpp"

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

Eigen::VectorXd von_mises_stress(const Eigen::MatrixXd& rest, const Eigen::MatrixXd& deformed,
                                 const Eigen::MatrixXi& tets, double youngs_modulus, double poisson_ratio) {
  if (!(youngs_modulus > 0.0) || !(poisson_ratio > -1.0 && poisson_ratio < 0.5))
    throw std::invalid_argument("von_mises_stress: need E > 0 and -1 < nu < 0.5, got E = " + std::to_string(youngs_modulus) +
                                ", nu = " + std::to_string(poisson_ratio));
  if (rest.rows() != deformed.rows() || rest.cols() != 3 || deformed.cols() != 3)
    throw std::invalid_argument("von_mises_stress: rest and deformed must both be #P by 3");
  const auto [mu, lambda] = lame_parameters(youngs_modulus, poisson_ratio);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(tets.rows());
  for (Eigen::Index t = 0; t < tets.rows(); ++t) {
    Eigen::Matrix3d dm, ds;
    for (int k = 0; k < 3; ++k) {
      dm.col(k) = (rest.row(tets(t, k + 1)) - rest.row(tets(t, 0))).transpose();
      ds.col(k) = (deformed.row(tets(t, k + 1)) - deformed.row(tets(t, 0))).transpose();
    }
    const double rest_det = dm.determinant();
    if (std::abs(rest_det) <= 1e-30) continue;
    // F = Ds Dm⁻¹
    const Eigen::Matrix3d F = ds * dm.inverse();
    const double J = F.determinant();
    if (!(J > 0.0)) continue;
    // σ = (μ/J)(b − I) + (λ ln J / J) I
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d sigma = (mu / J) * (F * F.transpose() - I) + (lambda * std::log(J) / J) * I;
    // σ_vM = sqrt(3/2 s:s)
    const Eigen::Matrix3d s = sigma - sigma.trace() / 3.0 * I;
    out(t) = std::sqrt(1.5 * s.cwiseProduct(s).sum());
  }
  return out;
}

} // namespace kerf
