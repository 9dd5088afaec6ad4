#pragma once
// How long the cohesive zone is, and whether a mesh resolves it — and which interaction mode of
// paper 001 §4.2 a reference sample is in, read from the mechanics of the cohesive interface.

#include "meshes/interaction_mode.hpp"

namespace kerf::reference {

/// Length of the cohesive (process) zone ahead of a crack tip in an infinite body,
///   l_cz = M E' J_c / σ_c²,  E' = E / (1 − ν²) (plane strain),
/// with M = 9π/32 ≈ 0.88 for a zone of constant traction (Rice 1980, "The mechanics of earthquake
/// rupture", Proc. Int. School of Physics "Enrico Fermi" 78; the estimate used by Falk, Needleman
/// & Rice 2001, J. Phys. IV 11, and by Turon et al. 2007, Eng. Fract. Mech. 74, Eq. 2, which also
/// recommends at least three elements in the zone). Units: Pa, J/m^2 → m.
double cohesive_zone_length(double youngs_modulus, double poisson_ratio, double fracture_toughness, double cohesive_strength);

/// Elements the zone spans at element size h (Turon et al. 2007: at least 3 for a converged
/// dissipation; kerf warns below that).
inline double elements_in_cohesive_zone(double zone_length, double element_size) { return zone_length / element_size; }
inline constexpr double minimum_elements_in_cohesive_zone = 3.0; ///< Turon et al. 2007, §2

/// What the reference knows at one sample to name its mode.
struct CohesiveSampleState {
  bool in_contact = false;     ///< the tool touches the body (contact points > 0)
  double failed_area = 0.0;    ///< cohesive area failed so far [m^2]
};

/// Paper 001 §4.2's modes from the cohesive interface, sample by sample:
///  no-contact    the tool does not touch the body;
///  deformation-1 in contact, nothing has failed yet (uncut material deforms);
///  rupture       the first sample at which any cohesive area has failed (the first unstable
///                opening: the crack appears);
///  cutting       in contact and the failed area grew since the previous sample (the front
///                advances with the tool);
///  deformation-2 in contact with a crack present and not growing (retreat, or re-entry into the
///                existing crack).
/// `previous` is the preceding sample (a default-constructed state before the first).
InteractionMode reference_mode(const CohesiveSampleState& previous, const CohesiveSampleState& current);

} // namespace kerf::reference
