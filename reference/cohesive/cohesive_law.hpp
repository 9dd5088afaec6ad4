#pragma once
// The traction–separation law of the reference's cohesive interface (issue 4): bilinear, with
// irreversible damage, a mixed-mode effective opening, contact of the crack faces in compression,
// and optional viscous regularisation.
//
// Form (Camacho & Ortiz 1996, "Computational modelling of impact damage in brittle materials",
// Int. J. Solids Struct. 33, §3, Eqs. 23–27; Ortiz & Pandolfi 1999, Int. J. Numer. Meth. Engng 44,
// §3, Eqs. 16–22), with the linear rising branch of the bilinear law (Park & Paulino 2011,
// "Cohesive zone models: a critical review of traction-separation relationships across fracture
// surfaces", Appl. Mech. Rev. 64, §3.1):
//
//   opening        Δ = x⁺ − x⁻ (the + face minus the − face, which coincide before opening)
//   components     δ_n = Δ·n (normal, n points from − into +),  δ_s = Δ − δ_n n (sliding)
//   effective      δ = sqrt(⟨δ_n⟩² + β² |δ_s|²)                       (Ortiz–Pandolfi Eq. 17)
//   envelope       T(δ) = σ_c δ/δ_0                     for δ ≤ δ_0
//                       = σ_c (δ_f − δ)/(δ_f − δ_0)     for δ_0 < δ < δ_f
//                       = 0                              for δ ≥ δ_f
//   toughness      J_c = ∫ T dδ = σ_c δ_f / 2  ⇒  δ_f = 2 J_c / σ_c
//   damage         κ = max over the history of δ (κ ≥ δ_0): the interface unloads along the secant
//                  to the origin and never heals; secant stiffness K(κ) = T(κ)/κ
//   traction       t = K(κ) (β² δ_s + ⟨δ_n⟩ n)                       (Ortiz–Pandolfi Eq. 19)
//   contact        + K_0 δ_n n  when δ_n < 0 (penalty against interpenetration, K_0 = σ_c/δ_0)
//   viscosity      + η w(κ_n) (Δ − Δ_n)/Δt  (Gao & Bower 2004, Modelling Simul. Mater. Sci. Eng. 12,
//                  453, Eq. 5: a viscous term that stabilises the softening branch; its dissipation
//                  is reported so it can be kept negligible). Δ_n, κ_n: the last converged step.
//                  w = 1 up to the peak, T(κ_n)/σ_c on the softening branch, 0 once failed: the
//                  viscous traction, like the cohesive one, fades with the strength left, so a
//                  separated point carries nothing (without w a failed interface stays a dashpot
//                  that holds the two halves together; taking κ at the start of the step keeps
//                  the tangent η w/Δt exact)
//
// ⟨x⟩ = max(x, 0). β weights sliding against opening (Camacho–Ortiz: the ratio of shear to normal
// strength; β = 1 treats modes I and II alike). The rising branch δ_0 is a penalty: small against
// δ_f, it makes the uncracked interface stiff against the bulk (the intrinsic law's artificial
// compliance, Park & Paulino 2011 §3.1), while keeping the tangent finite.

#include <Eigen/Core>

namespace kerf::reference {

/// Parameters of the bilinear law. SI units.
struct CohesiveLawParameters {
  double cohesive_strength = 0.0;   ///< σ_c [Pa] > 0: peak traction
  double fracture_toughness = 0.0;  ///< J_c [J/m^2] > 0: area under the envelope
  double initial_opening_ratio = 0.01; ///< δ_0 / δ_f in (0, 1): where the rising branch peaks
  double shear_weight = 1.0;        ///< β >= 0 of the effective opening
  double viscosity = 0.0;           ///< η [Pa s/m] >= 0 of the viscous regularisation

  [[nodiscard]] double failure_opening() const { return 2.0 * fracture_toughness / cohesive_strength; } ///< δ_f [m]
  [[nodiscard]] double peak_opening() const { return initial_opening_ratio * failure_opening(); }     ///< δ_0 [m]
  [[nodiscard]] double initial_stiffness() const { return cohesive_strength / peak_opening(); }       ///< K_0 [Pa/m]
};

/// Throws std::invalid_argument naming the parameter if it is out of range.
void validate(const CohesiveLawParameters& parameters);

/// The history of one interface point: the largest effective opening reached (κ, starts at δ_0)
/// and the opening at the end of the last converged step (for the viscous term).
struct CohesiveState {
  double max_opening = 0.0; ///< κ [m]; 0 means "not yet loaded" and is read as δ_0
  Eigen::Vector3d previous_opening = Eigen::Vector3d::Zero(); ///< Δ at the last converged step [m]
};

/// The law's answer at one point for a trial opening.
struct CohesiveResponse {
  Eigen::Vector3d traction = Eigen::Vector3d::Zero(); ///< t [Pa] that the − side exerts on the + side is −t
  Eigen::Matrix3d tangent = Eigen::Matrix3d::Zero();  ///< ∂t/∂Δ [Pa/m] (consistent with the damage update)
  double effective_opening = 0.0; ///< δ [m]
  double damage_opening = 0.0;    ///< κ after this trial (the new history if the step is accepted)
  double damage = 0.0;            ///< 1 − K(κ)/K_0 in [0, 1]
  bool failed = false;            ///< κ >= δ_f: the interface carries no tension here any more
  double stored_energy = 0.0;     ///< recoverable energy per area ½ K(κ) δ² + contact ½ K_0 ⟨−δ_n⟩² [J/m^2]
  double dissipated_energy = 0.0; ///< φ_d(κ) = ∫₀^κ T dδ − ½ T(κ) κ [J/m^2] (total, not the increment)
  double viscous_power_density = 0.0; ///< η w |Δ − Δ_prev|² / Δt² [W/m^2] (times Δt: viscous dissipation)
};

/// Evaluates the law at opening `opening` with unit normal `normal` (pointing from − into +),
/// history `state` and time step `dt` [s] (used by the viscous term only; dt <= 0 switches it off).
/// Pure: the caller commits `damage_opening` and the opening to the state when the step converges.
/// `secant_tangent` returns the secant K(κ) M (positive semi-definite, dropping the softening term)
/// instead of the consistent tangent: the robust fallback of a Newton iteration that cycles
/// between loading and unloading states (the "secant stiffness" iteration, e.g. de Borst et al.
/// 2012, Non-Linear Finite Element Analysis of Solids and Structures, §6.2).
CohesiveResponse cohesive_response(const CohesiveLawParameters& parameters, const CohesiveState& state,
                                   const Eigen::Vector3d& opening, const Eigen::Vector3d& normal, double dt,
                                   bool secant_tangent = false);

/// The weight w(κ) in [0, 1] of the viscous term at damage opening κ [m]: 1 for κ <= δ_0,
/// (δ_f − κ)/(δ_f − δ_0) = T(κ)/σ_c on the softening branch, 0 for κ >= δ_f (see the file comment).
double viscous_weight(const CohesiveLawParameters& parameters, double damage_opening);

/// The envelope T(δ) [Pa] and its dissipated energy φ_d(κ) [J/m^2] (closed forms of the bilinear law).
double cohesive_envelope(const CohesiveLawParameters& parameters, double effective_opening);
double cohesive_dissipation(const CohesiveLawParameters& parameters, double damage_opening);

} // namespace kerf::reference
