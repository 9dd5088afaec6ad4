#pragma once
// HyperelasticLaw: the constitutive interface of the finite-strain reference. A law maps the
// deformation gradient F to the strain energy density ψ(F), the first Piola–Kirchhoff stress
// P = ∂ψ/∂F and the first elasticity tensor 𝔸 = ∂P/∂F (total Lagrangian; Holzapfel 2000, §6.1
// and §6.6). Laws are written in terms of the right Cauchy–Green tensor C = FᵀF: the second
// Piola–Kirchhoff stress S = 2 ∂ψ/∂C and the material tangent ℂ = 2 ∂S/∂C, from which P and 𝔸
// follow by `first_piola_and_tangent`.

#include "meshes/lame_parameters.hpp"

#include <Eigen/Core>

namespace kerf::reference {

/// A fourth-order tensor over 3-D indices stored as a 9 by 9 matrix: entry (3i+J, 3k+L) is
/// T_iJkL. Used for ℂ (material indices IJKL) and 𝔸 (mixed indices iJkL).
using Tensor4 = Eigen::Matrix<double, 9, 9>;

/// Stress and tangent of a law at one deformation gradient.
struct StressTangent {
  Eigen::Matrix3d first_piola = Eigen::Matrix3d::Zero(); ///< P [Pa]
  Tensor4 tangent = Tensor4::Zero();                      ///< 𝔸 = ∂P/∂F [Pa], (3i+J, 3k+L)
};

/// Interface of one hyperelastic material law (one class per law, step-44's `Material_…`).
class HyperelasticLaw {
public:
  virtual ~HyperelasticLaw() = default;
  /// Strain energy per unit reference volume ψ(F) [J/m^3]. Requires det F > 0 for laws with ln J.
  [[nodiscard]] virtual double energy(const Eigen::Matrix3d& F) const = 0;
  /// Second Piola–Kirchhoff stress S = 2 ∂ψ/∂C [Pa] and material tangent ℂ = 2 ∂S/∂C [Pa].
  virtual void second_piola_and_tangent(const Eigen::Matrix3d& F, Eigen::Matrix3d& S, Tensor4& C4) const = 0;
  /// S alone, for the residual-only assemblies of the line search (the same S, bit for bit, as
  /// `second_piola_and_tangent`, without the cost of ℂ). The default calls that function.
  [[nodiscard]] virtual Eigen::Matrix3d second_piola(const Eigen::Matrix3d& F) const;
  /// P = F S and 𝔸 = ∂P/∂F (see `first_piola_and_tangent`).
  [[nodiscard]] StressTangent stress_and_tangent(const Eigen::Matrix3d& F) const;
};

/// From S and ℂ to P and 𝔸 (Holzapfel 2000, eq. 6.200 in index form):
///   P = F S,   𝔸_iJkL = δ_ik S_LJ + F_iI ℂ_IJKL F_kK.
StressTangent first_piola_and_tangent(const Eigen::Matrix3d& F, const Eigen::Matrix3d& S, const Tensor4& C4);

/// The symmetric tensor 𝕀_{C⁻¹} = −∂C⁻¹/∂C (Holzapfel 2000, eq. 6.166):
///   𝕀_IJKL = ½ (C⁻¹_IK C⁻¹_JL + C⁻¹_IL C⁻¹_JK).
Tensor4 inverse_derivative_tensor(const Eigen::Matrix3d& C_inv);

/// The dyadic product (A ⊗ B)_IJKL = A_IJ B_KL.
Tensor4 dyadic(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B);

/// Cauchy stress σ = J⁻¹ P Fᵀ [Pa].
Eigen::Matrix3d cauchy_stress(const Eigen::Matrix3d& F, const Eigen::Matrix3d& P);

/// Von Mises equivalent stress √(3/2 s:s), s = dev σ [Pa].
double von_mises(const Eigen::Matrix3d& sigma);

/// Lamé parameters (meshes/lame_parameters.hpp, the one definition every model shares).
using ::kerf::LameParameters;
using ::kerf::lame_parameters;

} // namespace kerf::reference
