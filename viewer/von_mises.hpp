#pragma once
// The von Mises stress of a deformed tetrahedral mesh, one value per tetrahedron, from the
// compressible neo-Hookean law the reference solver uses (reference/, docs/reference.md), so that
// a fast model's embedded mesh and the reference's fields are coloured by the same measure.

#include <Eigen/Core>

namespace kerf {

/// Per tetrahedron t (constant-strain P1 element):
///   F = Ds Dm⁻¹ (Ds, Dm: edge matrices of the deformed and rest tetrahedron), J = det F,
///   b = F Fᵀ,  σ = (μ/J)(b − I) + (λ ln J / J) I   (compressible neo-Hookean Cauchy stress;
///   Bonet & Wood, Nonlinear Continuum Mechanics for FE Analysis, 2nd ed., Eq. 5.29),
///   μ = E / (2(1 + ν)), λ = E ν / ((1 + ν)(1 − 2ν)),
///   σ_vM = sqrt(3/2 s:s),  s = σ − tr(σ)/3 I.
/// `rest`, `deformed`: #P by 3 [m]; `tets`: #T by 4; E [Pa] > 0, ν in (-1, 0.5). Returns #T
/// values [Pa]; an inverted or degenerate tetrahedron (J <= 0 or a singular rest shape) gets 0.
Eigen::VectorXd von_mises_stress(const Eigen::MatrixXd& rest, const Eigen::MatrixXd& deformed,
                                 const Eigen::MatrixXi& tets, double youngs_modulus, double poisson_ratio);

} // namespace kerf
