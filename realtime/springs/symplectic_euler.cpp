#include "realtime/springs/symplectic_euler.hpp"

#include "realtime/springs/network_system.hpp"

#include <Eigen/Geometry>

#include <algorithm>
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
  const auto K = system.matrix().selfadjointView<Eigen::Lower>();
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

double gershgorin_frequency_bound(const SpringNetwork& net, const Eigen::Matrix3Xd& x, std::vector<double>& work) noexcept {
  std::fill(work.begin(), work.begin() + net.node_count, 0.0);
  // Springs: the merged flat arrays (a merged spring's constant is the sum of its cells' ones,
  // and the row sums are linear in k).
  const SpringArrays& s = net.springs;
  for (int i = 0; i < s.count; ++i) {
    const int a = s.a[static_cast<std::size_t>(i)], b = s.b[static_cast<std::size_t>(i)];
    const double l = (x.col(b) - x.col(a)).norm();
    const double L = s.rest[static_cast<std::size_t>(i)];
    const double row = 2.0 * s.k[static_cast<std::size_t>(i)] * std::max(1.0, l > 0.0 ? std::abs(1.0 - L / l) : 1e6);
    work[static_cast<std::size_t>(a)] += row;
    work[static_cast<std::size_t>(b)] += row;
  }
  const double h = net.block.cell_size;
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0) {
    const double c = 1.0 / (4.0 * h);
    for (const auto& nodes : net.cell_nodes) {
      // F = Σ_a x_a ⊗ g_a, g_a = s_a / (4h), column by column.
      Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
      for (int a = 0; a < 8; ++a) {
        const auto xa = x.col(nodes[static_cast<std::size_t>(a)]);
        for (int i = 0; i < 3; ++i) F.col(i) += ((a >> i) & 1 ? c : -c) * xa;
      }
      Eigen::Matrix3d cof;
      cof.col(0) = F.col(1).cross(F.col(2));
      cof.col(1) = F.col(2).cross(F.col(0));
      cof.col(2) = F.col(0).cross(F.col(1));
      double norms[8], total = 0.0;
      for (int a = 0; a < 8; ++a) {
        const Eigen::Vector3d s_a(2.0 * (a & 1) - 1.0, 2.0 * ((a >> 1) & 1) - 1.0, 2.0 * ((a >> 2) & 1) - 1.0);
        norms[a] = c * (cof * s_a).norm(); // |∇_a J| = |cof(F) g_a|
        total += norms[a];
      }
      for (int a = 0; a < 8; ++a) work[static_cast<std::size_t>(nodes[static_cast<std::size_t>(a)])] += kappa * h * h * h * norms[a] * total;
    }
  }
  // An anchor adds K I to its node's diagonal block: K to the row.
  for (int i = 0; i < net.anchors.count(); ++i)
    work[static_cast<std::size_t>(net.anchors.node[static_cast<std::size_t>(i)])] += net.anchors.stiffness[static_cast<std::size_t>(i)];
  double bound = 0.0;
  for (int p = 0; p < net.node_count; ++p)
    if (net.constraint[static_cast<std::size_t>(p)] != fix_all)
      bound = std::max(bound, work[static_cast<std::size_t>(p)] / net.mass[static_cast<std::size_t>(p)]);
  return bound;
}

namespace {
/// v ← v + h f / m, then x ← x + h v, on the free axes.
void symplectic_euler_update(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             const Eigen::Matrix3Xd& f) noexcept {
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
}
} // namespace

double symplectic_euler_step(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             Eigen::Matrix3Xd& f) noexcept {
  const double energy = network_forces(net, x, v, f);
  symplectic_euler_update(net, x, v, h, f);
  return energy;
}

double symplectic_euler_step(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double h,
                             LatticeForces& forces, Eigen::Matrix3Xd& f) noexcept {
  const double energy = forces.evaluate(net, x, v, f);
  symplectic_euler_update(net, x, v, h, f);
  return energy;
}

} // namespace kerf
