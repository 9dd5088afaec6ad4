#pragma once
// Pre-sliding friction of Hayward & Armstrong, "A new computational model of friction applied to
// haptic rendering", Experimental Robotics VI, LNCIS 250, Springer 2000, §3.1 — the model paper
// 001 §6 uses for the knife's flanks and edge sliding against the body (its reference [16]).

namespace kerf {

/// One frictional contact along one direction. The contact's adhesion point w lags the tool
/// position x; the pre-sliding displacement z = x - w loads an elastic adhesion of stiffness k,
/// and the friction force on the tool is f = -k z. Per displacement increment dx:
///
///   dz = dx (1 - α(z) z / z_max)   if dx and z have the same sign (loading),
///   dz = dx                        otherwise (unloading is elastic),
///
/// with z_max = μ N / k the breakaway displacement, so steady sliding gives |f| = k z_max = μ N
/// (Coulomb), and the adhesion map α(z) = 0 for |z| <= z_stick (pure stick), 1 for
/// |z| >= z_max, and ½ sin(π (|z| - (z_max + z_stick)/2) / (z_max - z_stick)) + ½ between
/// (Hayward & Armstrong's smooth transition). z is kept within |z| <= z_max, and rescaled
/// when the normal force N drops. Allocation-free, branch-bounded.
class PreslidingFriction {
public:
  /// `stiffness` k [N/m] > 0, `stick_ratio` = z_stick / z_max in [0, 1).
  PreslidingFriction(double stiffness, double stick_ratio);

  /// Advances by the tool displacement `dx` [m] along the direction, under normal force
  /// `normal_force` N [N] >= 0 and friction coefficient `mu` >= 0, and returns the friction
  /// force on the tool along the direction [N] (opposing the pre-sliding displacement).
  double update(double dx, double normal_force, double mu);

  /// Forget the adhesion (contact lost).
  void reset() { m_z = 0.0; }

  [[nodiscard]] double presliding_displacement() const { return m_z; }
  [[nodiscard]] double stiffness() const { return m_stiffness; }

private:
  double m_stiffness;
  double m_stick_ratio;
  double m_z = 0.0;
};

} // namespace kerf
