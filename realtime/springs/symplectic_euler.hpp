#pragma once
// Symplectic (semi-implicit) Euler for the spring network, with the stability limit it computes
// from the network itself.

#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/spring_network.hpp"

#include <vector>

namespace kerf {

/// Highest angular frequency ω_max [rad/s] of the network linearised at rest over its free
/// degrees of freedom: the largest eigenvalue of M^(-1/2) K₀ M^(-1/2), by power iteration with a
/// Rayleigh quotient (a lower bound that converges to ω_max²). Allocates (construction time).
double highest_angular_frequency(const SpringNetwork& net);

/// The stability limit of symplectic Euler on a mode of frequency ω with stiffness-proportional
/// damping ζ = τ ω / 2 (the Kelvin–Voigt dashpots c = τ k): the amplification matrix of
/// v⁺ = v + h(−ω² x − 2ζω v), x⁺ = x + h v⁺ has |eigenvalues| <= 1 iff (Jury's criterion)
///   h <= (2 / ω) (√(1 + ζ²) − ζ),
/// which is 2/ω undamped [s].
double symplectic_euler_stability_limit(double omega_max, double damping_time);

/// Gershgorin bound on ω_max² [1/s²] of the network's current tangent: max over nodes of
///   (1/m_i) Σ_{springs at i} 2 k max(1, |1 − L/l|)  +  (1/m_i) Σ_{cells at i} κ h³ |∇_i J| Σ_b |∇_b J|,
/// (row sums of |K_T| with the transverse spring stiffness k(1 − L/l), which grows without bound
/// as a spring is crushed). `work` has one entry per node (capacity). Allocation-free. Used to
/// shorten the sub-step when the network has deformed far from rest (the rest-state limit is
/// scaled by √(G_rest / G_now)).
double gershgorin_frequency_bound(const SpringNetwork& net, const Eigen::Matrix3Xd& x, std::vector<double>& work) noexcept;

/// One step of length h [s]: v ← v + h M⁻¹ f(x, v), then x ← x + h v, on the free axes of the
/// nodes in use; fixed axes keep the x and v the caller set. `f` is workspace (3 x capacity).
/// Returns the elastic energy at the start of the step [J]. Allocation-free.
double symplectic_euler_step(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             Eigen::Matrix3Xd& f) noexcept;
/// The same step with the forces from `forces` (the vectorised lattice loops while the network
/// is untorn, network_forces after a tear). Allocation-free.
double symplectic_euler_step(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             LatticeForces& forces, Eigen::Matrix3Xd& f) noexcept;

} // namespace kerf
