#pragma once
// Spring constants of paper 000's cubic cell (28 springs: every pair of its 8 nodes) identified
// from the material's E and ν, and the per-cell volume term that lifts the Cauchy restriction.
// Derivation: docs/spring-network.md.

#include <Eigen/Core>

namespace kerf {

/// The constants of one cubic cell of edge h [m]:
/// - `edge`, `face_diagonal`, `body_diagonal`: spring constants [N/m] of the 12 edges (rest length
///   h), 12 face diagonals (h√2) and 4 body diagonals (h√3); linear springs f = k (l − L).
/// - `volume_modulus` κ [Pa]: the per-cell volume term W = ½ κ V₀ (J − 1)² (Teschner,
///   Heidelberger, Müller, Gross, "A versatile and robust model for geometrically complex
///   deformable solids", CGI 2004, volume energy E_V = ½ k_V ((V − V₀)/V₀)², with k_V = κ V₀ and
///   V/V₀ = J, the cell's trilinear Jacobian at its centre). Zero when the term is off.
struct CellStiffness {
  double edge = 0.0;
  double face_diagonal = 0.0;
  double body_diagonal = 0.0;
  double volume_modulus = 0.0;
};

/// What an identified cell represents at small strain.
struct CellIdentification {
  CellStiffness stiffness;
  double youngs_modulus = 0.0;   ///< E of the network [Pa]
  double poisson_ratio = 0.0;    ///< ν of the network (1/4 without the volume term: Cauchy relations)
  double bulk_modulus_error = 0.0; ///< K_network / K_material − 1 (0 when ν is matched)
};

/// Identifies the cell constants so that the network is isotropic at small strain with the
/// material's E [Pa] and, if `volume_term`, its ν as well (docs/spring-network.md):
///   homogenised tensor of the 28 springs  C11 = (4k₁ + 4k₂ + 4k₃/3)/h,  C12 = C44 = (2k₂ + 4k₃/3)/h;
///   isotropy C11 − C12 = 2 C44  ⇔  k₁ = k₂/2 + 2k₃/3; the free split is fixed by k₂ = k₃ = k;
///   springs only: λ = μ = 2E/5 (ν = 1/4), k = 3μh/10, k₁ = 7k/6;
///   with the volume term: μ = E/(2(1+ν)) from the springs and κ = λ − μ ≥ 0 (needs ν ≥ 1/4).
/// Throws std::invalid_argument for E ≤ 0, h ≤ 0, ν outside (−1, 0.5), or a volume term asked
/// for with ν < 1/4 (it would need κ < 0).
CellIdentification identify_cell_stiffness(double youngs_modulus, double poisson_ratio, double cell_size,
                                           bool volume_term);

/// The small-strain elasticity tensor of a cell in Voigt notation (xx, yy, zz, yz, xz, xy) [Pa],
/// summed directly over its 28 springs, C_ijkl = (1/h³) Σ k l² n_i n_j n_k n_l, plus κ δ_ij δ_kl
/// from the volume term. An independent check of `identify_cell_stiffness`.
Eigen::Matrix<double, 6, 6> cell_elasticity_tensor(const CellStiffness& stiffness, double cell_size);

} // namespace kerf
