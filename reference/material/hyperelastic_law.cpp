#include "reference/material/hyperelastic_law.hpp"

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

Eigen::Matrix3d HyperelasticLaw::second_piola(const Eigen::Matrix3d& F) const {
  Eigen::Matrix3d S;
  Tensor4 C4;
  second_piola_and_tangent(F, S, C4);
  return S;
}

StressTangent HyperelasticLaw::stress_and_tangent(const Eigen::Matrix3d& F) const {
  Eigen::Matrix3d S;
  Tensor4 C4;
  second_piola_and_tangent(F, S, C4);
  return first_piola_and_tangent(F, S, C4);
}

StressTangent first_piola_and_tangent(const Eigen::Matrix3d& F, const Eigen::Matrix3d& S, const Tensor4& C4) {
  StressTangent out;
  out.first_piola = F * S;
  // B_(IJ),(kL) = ℂ_IJKL F_kK, then 𝔸_(iJ),(kL) = F_iI B_(IJ),(kL) + δ_ik S_LJ.
  Eigen::Matrix<double, 9, 9> B = Eigen::Matrix<double, 9, 9>::Zero();
  for (int IJ = 0; IJ < 9; ++IJ)
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        double sum = 0.0;
        for (int K = 0; K < 3; ++K) sum += C4(IJ, 3 * K + L) * F(k, K);
        B(IJ, 3 * k + L) = sum;
      }
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int kL = 0; kL < 9; ++kL) {
        double sum = 0.0;
        for (int I = 0; I < 3; ++I) sum += F(i, I) * B(3 * I + J, kL);
        out.tangent(3 * i + J, kL) = sum;
      }
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int L = 0; L < 3; ++L) out.tangent(3 * i + J, 3 * i + L) += S(L, J);
  return out;
}

Tensor4 inverse_derivative_tensor(const Eigen::Matrix3d& Ci) {
  Tensor4 T;
  for (int I = 0; I < 3; ++I)
    for (int J = 0; J < 3; ++J)
      for (int K = 0; K < 3; ++K)
        for (int L = 0; L < 3; ++L) T(3 * I + J, 3 * K + L) = 0.5 * (Ci(I, K) * Ci(J, L) + Ci(I, L) * Ci(J, K));
  return T;
}

Tensor4 dyadic(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  Tensor4 T;
  for (int I = 0; I < 3; ++I)
    for (int J = 0; J < 3; ++J)
      for (int K = 0; K < 3; ++K)
        for (int L = 0; L < 3; ++L) T(3 * I + J, 3 * K + L) = A(I, J) * B(K, L);
  return T;
}

Eigen::Matrix3d cauchy_stress(const Eigen::Matrix3d& F, const Eigen::Matrix3d& P) {
  // σ = J⁻¹ P Fᵀ (Holzapfel 2000, eq. 3.8).
  return P * F.transpose() / F.determinant();
}

double von_mises(const Eigen::Matrix3d& sigma) {
  // σ_vM = √(3/2 s:s), s = σ − tr(σ)/3 I.
  const Eigen::Matrix3d s = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * s.cwiseProduct(s).sum());
}


} // namespace kerf::reference
