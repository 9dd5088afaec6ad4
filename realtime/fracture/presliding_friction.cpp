#include "realtime/fracture/presliding_friction.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace kerf {

PreslidingFriction::PreslidingFriction(double stiffness, double stick_ratio)
    : m_stiffness(stiffness), m_stick_ratio(stick_ratio) {
  if (!(stiffness > 0.0) || !std::isfinite(stiffness))
    throw std::invalid_argument("pre-sliding friction: stiffness must be positive and finite");
  if (!(stick_ratio >= 0.0 && stick_ratio < 1.0))
    throw std::invalid_argument("pre-sliding friction: stick ratio must be in [0, 1)");
}

double PreslidingFriction::update(double dx, double normal_force, double mu) {
  const double z_max = std::max(0.0, mu * normal_force) / m_stiffness;
  if (!(z_max > 0.0) || !std::isfinite(z_max) || !std::isfinite(dx)) {
    m_z = 0.0; // no normal load: no adhesion, no friction
    return 0.0;
  }
  const double z_stick = m_stick_ratio * z_max;
  const double abs_z = std::abs(m_z);
  double alpha = 0.0;
  if (abs_z >= z_max) {
    alpha = 1.0;
  } else if (abs_z > z_stick) {
    // Hayward & Armstrong's smooth adhesion map between stick and sliding.
    alpha = 0.5 * std::sin(std::numbers::pi * (abs_z - 0.5 * (z_max + z_stick)) / (z_max - z_stick)) + 0.5;
  }
  const bool loading = (dx > 0.0 && m_z >= 0.0) || (dx < 0.0 && m_z <= 0.0);
  m_z += loading ? dx * (1.0 - alpha * abs_z / z_max) : dx;
  m_z = std::clamp(m_z, -z_max, z_max); // discrete safeguard; exact in the continuous model
  return -m_stiffness * m_z;
}

} // namespace kerf
