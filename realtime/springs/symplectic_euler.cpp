#include "realtime/springs/symplectic_euler.hpp"

#include "realtime/springs/network_system.hpp"

#include <cmath>

namespace kerf {

double highest_angular_frequency(const SpringNetwork& net) {
  NetworkSystem system(net);
  const int n = system.dof_count();
  if (n == 0) return 0.0;
  system.assemble(net, net.rest, 0.0, 1.0);
  Eigen::VectorXd inv_sqrt_m(n);
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (const int d = system.dof_of()[static_cast<std::size_t>(3 * p + i)]; d >= 0)
        inv_sqrt_m[d] = 1.0 / std::sqrt(net.mass[static_cast<std::size_t>(p)]);
  const auto K = system.matrix().selfadjointView<Eigen::Upper>();
  // Power iteration on S = M^(-1/2) K M^(-1/2) from a deterministic, mode-rich start vector.
  Eigen::VectorXd u(n), w(n);
  for (int k = 0; k < n; ++k) u[k] = std::sin(1.0 + 12.9898 * k) + ((k % 2) ? 0.5 : -0.5);
  u.normalize();
  double rayleigh = 0.0;
  for (int it = 0; it < 2000; ++it) {
    w = inv_sqrt_m.asDiagonal() * (K * (inv_sqrt_m.asDiagonal() * u));
    const double next = u.dot(w); // Rayleigh quotient uᵀ S u, |u| = 1
    u = w.normalized();
    if (it > 50 && std::abs(next - rayleigh) <= 1e-10 * next) {
      rayleigh = next;
      break;
    }
    rayleigh = next;
  }
  return std::sqrt(std::max(rayleigh, 0.0));
}

double symplectic_euler_stability_limit(double omega_max, double damping_time) {
  if (!(omega_max > 0.0)) return INFINITY;
  const double zeta = 0.5 * damping_time * omega_max;
  // h <= (2/ω)(√(1+ζ²) − ζ)
  return 2.0 / omega_max * (std::sqrt(1.0 + zeta * zeta) - zeta);
}

double symplectic_euler_step(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             Eigen::Matrix3Xd& f) noexcept {
  const double energy = network_forces(net, x, v, f);
  for (int p = 0; p < net.node_count; ++p) {
    const std::uint8_t fixed = net.constraint[static_cast<std::size_t>(p)];
    const double inv_m = 1.0 / net.mass[static_cast<std::size_t>(p)];
    for (int i = 0; i < 3; ++i) {
      if (fixed & (1u << i)) continue;
      // v ← v + h f / m;  x ← x + h v
      v(i, p) += h * inv_m * f(i, p);
      x(i, p) += h * v(i, p);
    }
  }
  return energy;
}

} // namespace kerf
