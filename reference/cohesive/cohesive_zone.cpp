#include "reference/cohesive/cohesive_zone.hpp"

#include <numbers>
#include <stdexcept>

namespace kerf::reference {

double cohesive_zone_length(double E, double nu, double Jc, double sigma_c) {
  if (!(E > 0.0) || !(nu > -1.0 && nu < 0.5) || !(Jc > 0.0) || !(sigma_c > 0.0))
    throw std::invalid_argument("cohesive_zone_length: needs E > 0, ν in (−1, 0.5), J_c > 0 and σ_c > 0");
  const double plane_strain_modulus = E / (1.0 - nu * nu); // E'
  const double M = 9.0 * std::numbers::pi / 32.0;         // Rice 1980
  return M * plane_strain_modulus * Jc / (sigma_c * sigma_c);
}

InteractionMode reference_mode(const CohesiveSampleState& previous, const CohesiveSampleState& current) {
  // A crack "grows" when the failed area increases by more than round-off of the area sums.
  const double grown = current.failed_area - previous.failed_area;
  const bool growing = grown > 1e-12 * (current.failed_area + previous.failed_area) && grown > 0.0;
  if (current.failed_area > 0.0 && previous.failed_area <= 0.0) return InteractionMode::rupture;
  if (!current.in_contact) return InteractionMode::no_contact;
  if (current.failed_area <= 0.0) return InteractionMode::deformation_1;
  return growing ? InteractionMode::cutting : InteractionMode::deformation_2;
}

} // namespace kerf::reference
