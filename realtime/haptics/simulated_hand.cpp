#include "realtime/haptics/simulated_hand.hpp"

#include <cmath>
#include <stdexcept>

namespace kerf {

double HandParameters::damping() const { return 2.0 * damping_ratio * std::sqrt(stiffness * mass); }

SimulatedHand::SimulatedHand(const HandParameters& parameters, const Eigen::Vector3d& start)
    : m_p(parameters), m_b(parameters.damping()), m_x(start) {
  if (!(parameters.mass > 0.0) || !std::isfinite(parameters.mass))
    throw std::invalid_argument("simulated hand: mass must be positive");
  if (!(parameters.stiffness > 0.0) || !std::isfinite(parameters.stiffness))
    throw std::invalid_argument("simulated hand: stiffness must be positive");
  if (!(parameters.damping_ratio >= 0.0) || !std::isfinite(parameters.damping_ratio))
    throw std::invalid_argument("simulated hand: damping ratio must be >= 0");
}

void SimulatedHand::step(const Eigen::Vector3d& target, const Eigen::Vector3d& target_velocity,
                         const Eigen::Vector3d& force, double dt) noexcept {
  // m a = k (x_t - x) + b (v_t - v) + F; v += a dt; x += v dt (semi-implicit Euler).
  const Eigen::Vector3d a = (m_p.stiffness * (target - m_x) + m_b * (target_velocity - m_v) + force) / m_p.mass;
  m_v += a * dt;
  m_x += m_v * dt;
}

} // namespace kerf
