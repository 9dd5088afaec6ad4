#pragma once
// The simulated hand of `kerf-rig device-sim`: the device's handle held by an arm modelled as a
// point mass on a spring–damper that pulls it toward the target the hand means to follow,
//   m x'' = k (x_t - x) + b (v_t - v) + F_device,
// integrated with semi-implicit (symplectic) Euler, stable for sqrt(k_total / m) dt < 2.

#include <Eigen/Core>

namespace kerf {

/// Hand–arm parameters. Defaults: m = 0.2 kg, an estimate of the effective mass of a hand in a
/// pen grip plus a desktop device's handle (PHANToM-class devices have ~0.1 kg apparent mass);
/// k = 800 N/m, within the 300–1000 N/m hand stiffness measured by Mussa-Ivaldi, Hogan & Bizzi
/// (1985, J. Neurosci. 5(10)) for postural arm control; damping ratio 0.7 (estimate).
struct HandParameters {
  double mass = 0.2;          ///< [kg] > 0
  double stiffness = 800.0;   ///< [N/m] > 0
  double damping_ratio = 0.7; ///< b = 2 zeta sqrt(k m), >= 0
  /// b [N s/m]
  [[nodiscard]] double damping() const;
};

class SimulatedHand {
public:
  /// Throws std::invalid_argument naming a non-positive mass or stiffness or a negative ratio.
  SimulatedHand(const HandParameters& parameters, const Eigen::Vector3d& start);

  /// Advances by dt [s] under the device force `force` [N] (the force on the handle), following
  /// the target position [m] and velocity [m/s].
  void step(const Eigen::Vector3d& target, const Eigen::Vector3d& target_velocity, const Eigen::Vector3d& force,
            double dt) noexcept;

  [[nodiscard]] const Eigen::Vector3d& position() const noexcept { return m_x; }
  [[nodiscard]] const Eigen::Vector3d& velocity() const noexcept { return m_v; }

private:
  HandParameters m_p;
  double m_b;
  Eigen::Vector3d m_x;
  Eigen::Vector3d m_v = Eigen::Vector3d::Zero();
};

} // namespace kerf
