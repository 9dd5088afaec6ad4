#include "realtime/springs/spring_network.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

const std::array<CellSpring, 28> cell_springs = [] {
  std::array<CellSpring, 28> s{};
  int n = 0;
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) s[n++] = {a, b, __builtin_popcount(static_cast<unsigned>(a ^ b))};
  return s;
}();

namespace {
/// s_a: the sign vector of local corner a, (2bx − 1, 2by − 1, 2bz − 1).
Eigen::Vector3d corner_sign(int a) { return {2.0 * (a & 1) - 1.0, 2.0 * ((a >> 1) & 1) - 1.0, 2.0 * ((a >> 2) & 1) - 1.0}; }

Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F) {
  Eigen::Matrix3d c;
  c.col(0) = F.col(1).cross(F.col(2));
  c.col(1) = F.col(2).cross(F.col(0));
  c.col(2) = F.col(0).cross(F.col(1));
  return c;
}
} // namespace

double SpringNetwork::rest_length(int type) const { return block.cell_size * std::sqrt(static_cast<double>(type)); }

double SpringNetwork::spring_constant(int type) const {
  return type == 1 ? stiffness.edge : type == 2 ? stiffness.face_diagonal : stiffness.body_diagonal;
}

int SpringNetwork::cell_at_index(const Eigen::Vector3i& g) const {
  const Eigen::Vector3i& n = block.cells;
  if ((g.array() < 0).any() || (g.array() >= n.array()).any()) return -1;
  return cell_at[static_cast<std::size_t>(g.x() + n.x() * (g.y() + n.y() * g.z()))];
}

SpringNetwork build_spring_network(const NetworkBlock& block, const std::vector<bool>& keep,
                                   const CellStiffness& stiffness, double density, double damping_time) {
  const Eigen::Vector3i& n = block.cells;
  if ((n.array() < 1).any() || !(block.cell_size > 0.0))
    throw std::invalid_argument("build_spring_network: the block needs >= 1 cell per axis and a cell size > 0");
  const std::size_t total = static_cast<std::size_t>(n.x()) * n.y() * n.z();
  if (keep.size() != total)
    throw std::invalid_argument("build_spring_network: keep has " + std::to_string(keep.size()) + " entries, the block " +
                                std::to_string(total) + " cells");
  if (!(density > 0.0)) throw std::invalid_argument("build_spring_network: density must be > 0");
  if (!(damping_time >= 0.0)) throw std::invalid_argument("build_spring_network: damping time must be >= 0");

  SpringNetwork net;
  net.block = block;
  net.stiffness = stiffness;
  const double h = block.cell_size;
  net.cell_mass = density * h * h * h;
  net.damping_time = damping_time;
  net.cell_at.assign(total, -1);
  const Eigen::Vector3i np = n + Eigen::Vector3i::Ones();
  std::vector<int> node_of_point(static_cast<std::size_t>(np.x()) * np.y() * np.z(), -1);
  std::vector<Eigen::Vector3d> positions;
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        if (!keep[static_cast<std::size_t>(i + n.x() * (j + n.y() * k))]) continue;
        std::array<int, 8> corners{};
        for (int a = 0; a < 8; ++a) {
          const Eigen::Vector3i p(i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1));
          int& id = node_of_point[static_cast<std::size_t>(p.x() + np.x() * (p.y() + np.y() * p.z()))];
          if (id < 0) {
            id = static_cast<int>(positions.size());
            positions.push_back(block.origin + h * p.cast<double>());
          }
          corners[static_cast<std::size_t>(a)] = id;
        }
        net.cell_at[static_cast<std::size_t>(i + n.x() * (j + n.y() * k))] = net.cell_count();
        net.cell_index.emplace_back(i, j, k);
        net.cell_nodes.push_back(corners);
      }
  if (net.cell_nodes.empty()) throw std::invalid_argument("build_spring_network: no cell is kept");
  // Capacity: every corner of every cell its own node (a fully torn network).
  const int capacity = 8 * net.cell_count();
  net.node_count = static_cast<int>(positions.size());
  net.rest.setZero(3, capacity);
  for (int p = 0; p < net.node_count; ++p) net.rest.col(p) = positions[static_cast<std::size_t>(p)];
  net.mass.assign(static_cast<std::size_t>(capacity), 0.0);
  for (const auto& corners : net.cell_nodes)
    for (int id : corners) net.mass[static_cast<std::size_t>(id)] += net.cell_mass / 8.0;
  net.constraint.assign(static_cast<std::size_t>(capacity), 0);
  const std::size_t springs = 28 * static_cast<std::size_t>(net.cell_count());
  for (std::vector<int>* v : {&net.springs.a, &net.springs.b}) v->assign(springs, 0);
  for (std::vector<double>* v : {&net.springs.k, &net.springs.rest}) v->assign(springs, 0.0);
  net.springs.key.assign(springs, 0);
  net.springs.key_merged.assign(springs, 0);
  merge_springs(net);
  return net;
}

namespace {

/// A topology value no network has had before in this process (SpringNetwork::topology): a copy
/// of a network taken before a tear and torn again differently never shows a value seen with
/// other corners, so the caches keyed by it (the kept sorted keys, VertexTearing's shared
/// springs, LatticeForces' exceptions) cannot mistake one network for the other. Lock-free.
std::uint64_t next_topology() noexcept {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}

/// The spring arrays from the cells' sorted keys: equal keys merged with summed constants.
void springs_from_sorted_keys(SpringNetwork& net) noexcept {
  SpringArrays& s = net.springs;
  // The constant travels with the key (its kind's): no cell index is needed beside it.
  const std::size_t n = 28 * static_cast<std::size_t>(net.cell_count());
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t key = s.key[i];
    const auto [a, b, type] = spring_of_key(key);
    if (i > 0 && key == s.key[i - 1]) {
      s.k[static_cast<std::size_t>(count - 1)] += net.spring_constant(type);
      continue;
    }
    s.a[static_cast<std::size_t>(count)] = a;
    s.b[static_cast<std::size_t>(count)] = b;
    s.k[static_cast<std::size_t>(count)] = net.spring_constant(type);
    s.rest[static_cast<std::size_t>(count)] = net.rest_length(type);
    ++count;
  }
  s.count = count;
  net.topology = next_topology();
  s.key_topology = net.topology;
}

} // namespace

void merge_springs(SpringNetwork& net) noexcept {
  SpringArrays& s = net.springs;
  const std::size_t n = 28 * static_cast<std::size_t>(net.cell_count());
  std::size_t m = 0;
  for (const auto& nodes : net.cell_nodes)
    for (const CellSpring& cs : cell_springs)
      s.key[m++] = spring_key(nodes[static_cast<std::size_t>(cs.a)], nodes[static_cast<std::size_t>(cs.b)], cs.type);
  std::sort(s.key.begin(), s.key.begin() + static_cast<std::ptrdiff_t>(n));
  springs_from_sorted_keys(net);
}

void merge_springs_after_split(SpringNetwork& net, int original, int copy) noexcept {
  SpringArrays& s = net.springs;
  const std::size_t n = 28 * static_cast<std::size_t>(net.cell_count());
  if (s.key_topology != net.topology || s.key_merged.size() < n) return merge_springs(net);
  // The keys the split changes: each moved cell's 7 springs at the copy's corner, before (at
  // the original) and after. A vertex is a corner of at most 8 cells.
  constexpr int most = 8 * 7;
  std::array<std::uint64_t, most> removed{}, added{};
  int changes = 0;
  for (const auto& nodes : net.cell_nodes)
    for (const CellSpring& cs : cell_springs) {
      const int p = nodes[static_cast<std::size_t>(cs.a)], q = nodes[static_cast<std::size_t>(cs.b)];
      if (p != copy && q != copy) continue;
      if (changes == most) return merge_springs(net);
      removed[static_cast<std::size_t>(changes)] = spring_key(p == copy ? original : p, q == copy ? original : q, cs.type);
      added[static_cast<std::size_t>(changes)] = spring_key(p, q, cs.type);
      ++changes;
    }
  std::sort(removed.begin(), removed.begin() + changes);
  std::sort(added.begin(), added.begin() + changes);
  // One pass over the kept keys: the removed ones left out (each once: a multiset difference),
  // the added ones merged in.
  std::size_t m = 0;
  int r = 0, a = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t key = s.key[i];
    if (r < changes && removed[static_cast<std::size_t>(r)] == key) {
      ++r;
      continue;
    }
    if (r < changes && removed[static_cast<std::size_t>(r)] < key) return merge_springs(net); // not among the kept keys
    while (a < changes && added[static_cast<std::size_t>(a)] <= key) s.key_merged[m++] = added[static_cast<std::size_t>(a++)];
    s.key_merged[m++] = key;
  }
  if (r < changes) return merge_springs(net);
  while (a < changes) s.key_merged[m++] = added[static_cast<std::size_t>(a++)];
  std::swap(s.key, s.key_merged);
  springs_from_sorted_keys(net);
}

Eigen::Matrix3d cell_deformation_gradient(const Eigen::Matrix<double, 3, 8>& corners, double h) {
  // F = Σ_a x_a ⊗ g_a, g_a = s_a / (4h): column j is (Σ_{a: bit j of a set} x_a − Σ_{others} x_a) / (4h).
  const Eigen::Vector3d x0 = corners.col(0), x1 = corners.col(1), x2 = corners.col(2), x3 = corners.col(3);
  const Eigen::Vector3d x4 = corners.col(4), x5 = corners.col(5), x6 = corners.col(6), x7 = corners.col(7);
  const double w = 0.25 / h;
  Eigen::Matrix3d F;
  F.col(0) = w * ((x1 - x0) + (x3 - x2) + (x5 - x4) + (x7 - x6));
  F.col(1) = w * ((x2 - x0) + (x3 - x1) + (x6 - x4) + (x7 - x5));
  F.col(2) = w * ((x4 - x0) + (x5 - x1) + (x6 - x2) + (x7 - x3));
  return F;
}

namespace {

/// The per-cell volume term of one cell with corners `x`, velocities `v` (docs/spring-network.md):
/// W = ½ κ V₀ (J − 1)², f_a = −κ V₀ ((J − 1) + τ J̇) cof(F) g_a, added to `f`; returns W.
double add_cell_volume_forces(double kappa, double tau, double h, const Eigen::Matrix<double, 3, 8>& x,
                              const Eigen::Matrix<double, 3, 8>& v, Eigen::Matrix<double, 3, 8>& f) noexcept {
  const double V0 = h * h * h;
  const Eigen::Matrix3d F = cell_deformation_gradient(x, h);
  const double J = F.determinant();
  const Eigen::Matrix3d cof = cofactor(F);
  Eigen::Matrix<double, 3, 8> dJ; // ∂J/∂x_a = cof(F) g_a
  double J_rate = 0.0;
  for (int a = 0; a < 8; ++a) {
    dJ.col(a) = cof * (corner_sign(a) / (4.0 * h));
    J_rate += dJ.col(a).dot(v.col(a));
  }
  // f_a = −κ V₀ ((J − 1) + τ J̇) cof(F) g_a
  const double pressure = kappa * V0 * ((J - 1.0) + tau * J_rate);
  f -= pressure * dJ;
  return 0.5 * kappa * V0 * (J - 1.0) * (J - 1.0);
}

} // namespace

double cell_forces(const SpringNetwork& net, int cell, const Eigen::Matrix<double, 3, 8>& x,
                   const Eigen::Matrix<double, 3, 8>& v, Eigen::Matrix<double, 3, 8>& f) noexcept {
  (void)cell;
  f.setZero();
  double energy = 0.0;
  const double tau = net.damping_time;
  const double L[4] = {0.0, net.rest_length(1), net.rest_length(2), net.rest_length(3)};
  const double K[4] = {0.0, net.stiffness.edge, net.stiffness.face_diagonal, net.stiffness.body_diagonal};
  for (const CellSpring& s : cell_springs) {
    const Eigen::Vector3d e = x.col(s.b) - x.col(s.a);
    const double l = e.norm();
    if (!(l > 1e-12 * L[1])) continue; // coincident ends: no direction, no force
    const Eigen::Vector3d d = e / l;
    const double k = K[s.type];
    const double stretch = l - L[s.type];
    // f_a = k (l − L) d + τ k ((v_b − v_a)·d) d
    const Eigen::Vector3d fa = (k * stretch + tau * k * (v.col(s.b) - v.col(s.a)).dot(d)) * d;
    f.col(s.a) += fa;
    f.col(s.b) -= fa;
    energy += 0.5 * k * stretch * stretch;
  }
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0) energy += add_cell_volume_forces(kappa, tau, net.block.cell_size, x, v, f);
  return energy;
}

void cell_stiffness_matrix(const SpringNetwork& net, int cell, const Eigen::Matrix<double, 3, 8>& x,
                           Eigen::Matrix<double, 24, 24>& K, CellTangent tangent) noexcept {
  (void)cell;
  const bool exact = tangent == CellTangent::exact;
  K.setZero();
  for (const CellSpring& s : cell_springs) {
    const Eigen::Vector3d e = x.col(s.b) - x.col(s.a);
    const double l = e.norm();
    const double L = net.rest_length(s.type);
    const double k = net.spring_constant(s.type);
    if (!(l > 1e-12 * L)) continue;
    const Eigen::Vector3d d = e / l;
    const Eigen::Matrix3d dd = d * d.transpose();
    // K_aa = k [d dᵀ + g (I − d dᵀ)],  g = 1 − L/l  (projected: max(0, g))
    const double g = exact ? 1.0 - L / l : std::max(0.0, 1.0 - L / l);
    const Eigen::Matrix3d Kaa = k * (dd + g * (Eigen::Matrix3d::Identity() - dd));
    K.block<3, 3>(3 * s.a, 3 * s.a) += Kaa;
    K.block<3, 3>(3 * s.b, 3 * s.b) += Kaa;
    K.block<3, 3>(3 * s.a, 3 * s.b) -= Kaa;
    K.block<3, 3>(3 * s.b, 3 * s.a) -= Kaa;
  }
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0) {
    const double h = net.block.cell_size;
    const double V0 = h * h * h;
    const Eigen::Matrix3d F = cell_deformation_gradient(x, h);
    const Eigen::Matrix3d cof = cofactor(F);
    Eigen::Matrix<double, 24, 1> dJ;
    for (int a = 0; a < 8; ++a) dJ.segment<3>(3 * a) = cof * (corner_sign(a) / (4.0 * h));
    // κ V₀ ∇J ∇Jᵀ
    K.noalias() += kappa * V0 * dJ * dJ.transpose();
    if (exact) {
      // κ V₀ (J − 1) ∂²J/∂x_a∂x_b:  [i][k] = ε_ikm w_m,  w = F (g_a × g_b)
      const double scale = kappa * V0 * (F.determinant() - 1.0);
      for (int a = 0; a < 8; ++a)
        for (int b = a + 1; b < 8; ++b) {
          const Eigen::Vector3d w = scale * (F * (corner_sign(a) / (4.0 * h)).cross(corner_sign(b) / (4.0 * h)));
          Eigen::Matrix3d H;
          H << 0.0, w.z(), -w.y(), -w.z(), 0.0, w.x(), w.y(), -w.x(), 0.0;
          K.block<3, 3>(3 * a, 3 * b) += H;
          K.block<3, 3>(3 * b, 3 * a) += H.transpose(); // g_b × g_a = −(g_a × g_b); the diagonal blocks vanish
        }
    }
  }
}

double network_forces(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                      Eigen::Matrix3Xd& f) noexcept {
  f.leftCols(net.node_count).setZero();
  double energy = 0.0;
  const double tau = net.damping_time;
  const double tiny = 1e-12 * net.block.cell_size;
  const double* xd = x.data();
  const double* vd = v.data();
  double* fd = f.data();
  const SpringArrays& s = net.springs;
  const int* sa = s.a.data();
  const int* sb = s.b.data();
  const double* sk = s.k.data();
  const double* sl = s.rest.data();
  for (int i = 0; i < s.count; ++i) {
    const int a = 3 * sa[i], b = 3 * sb[i];
    const double ex = xd[b] - xd[a], ey = xd[b + 1] - xd[a + 1], ez = xd[b + 2] - xd[a + 2];
    const double l = std::sqrt(ex * ex + ey * ey + ez * ez);
    const double inv_l = l > tiny ? 1.0 / l : 0.0; // coincident ends: no direction, no force
    const double stretch = l - sl[i];
    const double rate = (vd[b] - vd[a]) * ex + (vd[b + 1] - vd[a + 1]) * ey + (vd[b + 2] - vd[a + 2]) * ez;
    // f_a = k (l − L) d + τ k ((v_b − v_a)·d) d,  d = e / l
    const double scale = sk[i] * (stretch + tau * rate * inv_l) * inv_l;
    fd[a] += scale * ex, fd[a + 1] += scale * ey, fd[a + 2] += scale * ez;
    fd[b] -= scale * ex, fd[b + 1] -= scale * ey, fd[b + 2] -= scale * ez;
    energy += 0.5 * sk[i] * stretch * stretch * (inv_l > 0.0 ? 1.0 : 0.0);
  }
  const double kappa = net.stiffness.volume_modulus;
  if (kappa > 0.0) {
    Eigen::Matrix<double, 3, 8> xc, vc, fc;
    for (const auto& nodes : net.cell_nodes) {
      for (int a = 0; a < 8; ++a) {
        xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
        vc.col(a) = v.col(nodes[static_cast<std::size_t>(a)]);
      }
      fc.setZero();
      energy += add_cell_volume_forces(kappa, tau, net.block.cell_size, xc, vc, fc);
      for (int a = 0; a < 8; ++a) f.col(nodes[static_cast<std::size_t>(a)]) += fc.col(a);
    }
  }
  return energy + add_anchor_forces(net, x, v, f);
}

double add_anchor_forces(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                         Eigen::Matrix3Xd& f) noexcept {
  const NodeAnchors& anchors = net.anchors;
  const double tau = net.damping_time;
  double energy = 0.0;
  for (int i = 0; i < anchors.count(); ++i) {
    const int p = anchors.node[static_cast<std::size_t>(i)];
    const double K = anchors.stiffness[static_cast<std::size_t>(i)];
    const Eigen::Vector3d gap = anchors.position.col(i) - x.col(p);
    // f = K (a − x) + τ K (ȧ − v)
    f.col(p) += K * (gap + tau * (anchors.velocity.col(i) - v.col(p)));
    energy += 0.5 * K * gap.squaredNorm();
  }
  return energy;
}

} // namespace kerf
