#include "realtime/springs/vertex_tearing.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <stdexcept>

namespace kerf {

Eigen::Matrix3d cell_stress(const SpringNetwork& net, const Eigen::Matrix<double, 3, 8>& x) noexcept {
  const double h = net.block.cell_size;
  const double V0 = h * h * h;
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  for (const CellSpring& s : cell_springs) {
    const Eigen::Vector3d e = x.col(s.b) - x.col(s.a);
    const double l = e.norm();
    if (!(l > 0.0)) continue;
    // k (l − L) l d ⊗ d / V₀ = k (l − L) e ⊗ e / (l V₀)
    sigma += net.spring_constant(s.type) * (l - net.rest_length(s.type)) / (l * V0) * (e * e.transpose());
  }
  if (net.stiffness.volume_modulus > 0.0)
    sigma.diagonal().array() += net.stiffness.volume_modulus * (cell_deformation_gradient(x, h).determinant() - 1.0);
  return sigma;
}

int network_pieces(const SpringNetwork& net, std::vector<int>& parent, std::vector<int>& label) noexcept {
  const auto find = [&parent](int a) {
    while (parent[static_cast<std::size_t>(a)] != a) a = parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
    return a;
  };
  for (int p = 0; p < net.node_count; ++p) parent[static_cast<std::size_t>(p)] = p;
  for (const auto& nodes : net.cell_nodes)
    for (int a = 1; a < 8; ++a) {
      const int r0 = find(nodes[0]), r1 = find(nodes[static_cast<std::size_t>(a)]);
      if (r0 != r1) parent[static_cast<std::size_t>(r1)] = r0;
    }
  for (int c = 0; c < net.cell_count(); ++c) label[static_cast<std::size_t>(c)] = find(net.cell_nodes[static_cast<std::size_t>(c)][0]);
  // Every node in use belongs to a cell, so the pieces are the roots.
  int pieces = 0;
  for (int p = 0; p < net.node_count; ++p) pieces += find(p) == p ? 1 : 0;
  return pieces;
}

VertexTearing::VertexTearing(const SpringNetwork& net, double tensile_limit) : m_limit(tensile_limit) {
  if (!(tensile_limit > 0.0)) throw std::invalid_argument("VertexTearing: the tensile limit must be > 0 Pa");
  m_stress.assign(static_cast<std::size_t>(net.node_capacity()), Eigen::Matrix3d::Zero());
  m_cells.assign(static_cast<std::size_t>(net.node_capacity()), 0);
  m_opened.assign(static_cast<std::size_t>(net.node_capacity()), 0);
  const auto springs = 28 * static_cast<std::size_t>(net.cell_count());
  m_spring_of.assign(springs, 0);
  m_shared.assign(springs, {0, 0, 0});
  m_term.assign(springs, Eigen::Matrix3d::Zero());
  m_apart.assign(springs, 0);
  m_pairing.assign(springs, {0, 0});
  share_springs(net);
}

void VertexTearing::share_springs(const SpringNetwork& net) noexcept {
  // Each cell spring's key (spring_key, as merge_springs keys them) beside its index.
  std::size_t m = 0;
  for (const auto& nodes : net.cell_nodes)
    for (const CellSpring& cs : cell_springs) {
      m_pairing[m] = {spring_key(nodes[static_cast<std::size_t>(cs.a)], nodes[static_cast<std::size_t>(cs.b)], cs.type), static_cast<int>(m)};
      ++m;
    }
  std::sort(m_pairing.begin(), m_pairing.begin() + static_cast<std::ptrdiff_t>(m));
  m_shared_count = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint64_t key = m_pairing[i].first;
    if (i == 0 || key != m_pairing[i - 1].first) m_shared[static_cast<std::size_t>(m_shared_count++)] = spring_of_key(key);
    m_spring_of[static_cast<std::size_t>(m_pairing[i].second)] = m_shared_count - 1;
  }
  m_topology = net.topology;
}

void VertexTearing::share_springs_after_split(const SpringNetwork& net, int copy) noexcept {
  // Only the springs at the copy changed (their cells moved to it); they are shared among the
  // moved cells alone. A spring that no cell uses any more keeps its slot (computed, unread).
  const int first = m_shared_count;
  for (int c = 0; c < net.cell_count(); ++c) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(c)];
    for (int k = 0; k < 28; ++k) {
      const CellSpring& cs = cell_springs[static_cast<std::size_t>(k)];
      const int p = nodes[static_cast<std::size_t>(cs.a)], q = nodes[static_cast<std::size_t>(cs.b)];
      if (p != copy && q != copy) continue;
      const std::array<int, 3> spring = spring_of_key(spring_key(p, q, cs.type));
      int id = first;
      while (id < m_shared_count && m_shared[static_cast<std::size_t>(id)] != spring) ++id;
      if (id == m_shared_count) {
        if (m_shared_count == static_cast<int>(m_shared.size())) { // no slot left: pair them all again
          share_springs(net);
          return;
        }
        m_shared[static_cast<std::size_t>(m_shared_count++)] = spring;
      }
      m_spring_of[static_cast<std::size_t>(28 * c + k)] = id;
    }
  }
  m_topology = net.topology;
}

void VertexTearing::sum_cell_stresses(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept {
  if (net.topology != m_topology) share_springs(net); // cells changed other than by `tear`
  const double h = net.block.cell_size;
  const double V0 = h * h * h;
  // Each shared spring's term, the numbers cell_stress adds for it: Eigen evaluates its
  // `σ += c (e eᵀ)` entry by entry as (c e_i) e_j. A spring's term is the same for e and −e, so a
  // cell that runs the spring the other way adds the same numbers.
  const double k[4] = {0.0, net.spring_constant(1), net.spring_constant(2), net.spring_constant(3)};
  const double L[4] = {0.0, net.rest_length(1), net.rest_length(2), net.rest_length(3)};
  for (int u = 0; u < m_shared_count; ++u) {
    const auto& [a, b, type] = m_shared[static_cast<std::size_t>(u)];
    const Eigen::Vector3d e = x.col(b) - x.col(a);
    const double l = e.norm();
    m_apart[static_cast<std::size_t>(u)] = l > 0.0 ? 1 : 0;
    if (!(l > 0.0)) continue;
    const double c = k[type] * (l - L[type]) / (l * V0);
    const double ce[3] = {c * e[0], c * e[1], c * e[2]};
    double* term = m_term[static_cast<std::size_t>(u)].data(); // column-major: (i, j) at i + 3 j
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) term[i + 3 * j] = ce[i] * e[j];
  }
  const int n = net.node_count;
  for (int p = 0; p < n; ++p) {
    m_stress[static_cast<std::size_t>(p)].setZero();
    m_cells[static_cast<std::size_t>(p)] = 0;
  }
  Eigen::Matrix<double, 3, 8> xc;
  for (int c = 0; c < net.cell_count(); ++c) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(c)];
    // cell_stress: the springs' terms in cell_springs' order, then the volume term.
    Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
    const int* of = m_spring_of.data() + 28 * static_cast<std::size_t>(c);
    for (int j = 0; j < 28; ++j)
      if (m_apart[static_cast<std::size_t>(of[j])]) sigma += m_term[static_cast<std::size_t>(of[j])];
    if (net.stiffness.volume_modulus > 0.0) {
      for (int a = 0; a < 8; ++a) xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
      sigma.diagonal().array() += net.stiffness.volume_modulus * (cell_deformation_gradient(xc, h).determinant() - 1.0);
    }
    for (int id : nodes) {
      m_stress[static_cast<std::size_t>(id)] += sigma;
      ++m_cells[static_cast<std::size_t>(id)];
    }
  }
}

bool VertexTearing::tear(SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v,
                         const std::vector<std::uint8_t>& excluded) noexcept {
  const int n = net.node_count;
  sum_cell_stresses(net, x);
  Eigen::Matrix<double, 3, 8> xc;
  // The vertex stress: the mean of its cells' stresses; σ₁ its largest principal value.
  int worst = -1;
  double worst_stress = -INFINITY;
  Eigen::Vector3d worst_direction = Eigen::Vector3d::UnitX();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  m_last_max = 0.0;
  for (int p = 0; p < n; ++p) {
    const int count = m_cells[static_cast<std::size_t>(p)];
    if (count < 2 || excluded[static_cast<std::size_t>(p)] || m_opened[static_cast<std::size_t>(p)]) continue;
    const Eigen::Matrix3d sigma = m_stress[static_cast<std::size_t>(p)] / count;
    // σ₁ ≤ |σ|_F: a vertex whose norm is within the largest σ₁ so far can neither raise it nor,
    // above the limit, exceed the worst one (which is that largest σ₁ once one is found).
    if (sigma.norm() <= m_last_max) continue;
    eigen.computeDirect(sigma);
    const double s1 = eigen.eigenvalues()[2];
    m_last_max = std::max(m_last_max, s1);
    if (s1 > m_limit && s1 > worst_stress) {
      worst = p;
      worst_stress = s1;
      worst_direction = eigen.eigenvectors().col(2);
    }
  }
  if (worst < 0) return false;
  if (net.node_count >= net.node_capacity()) return false;

  // Group the cells at the vertex by the sign of their own force on it along n₁ (paper 000
  // §2.2: "whether the contribution of each cell to the stress is positive or negative"); when
  // that leaves one group empty (the contributions do not separate), by the cell's side of the
  // vertex along n₁.
  Eigen::Matrix<double, 3, 8> vc = Eigen::Matrix<double, 3, 8>::Zero(), fc;
  const auto along = [&](const std::array<int, 8>& nodes, int a, bool by_force) {
    for (int b = 0; b < 8; ++b) xc.col(b) = x.col(nodes[static_cast<std::size_t>(b)]);
    if (by_force) {
      cell_forces(net, 0, xc, vc, fc);
      return fc.col(a).dot(worst_direction);
    }
    return (xc.rowwise().mean() - x.col(worst)).dot(worst_direction);
  };
  bool by_force = true;
  int plus = 0, minus = 0;
  for (int pass = 0; pass < 2; ++pass) {
    by_force = pass == 0;
    plus = minus = 0;
    for (const auto& nodes : net.cell_nodes)
      for (int a = 0; a < 8; ++a)
        if (nodes[static_cast<std::size_t>(a)] == worst) (along(nodes, a, by_force) > 0.0 ? plus : minus) += 1;
    if (plus > 0 && minus > 0) break;
  }
  if (plus == 0 || minus == 0) return false;
  // Split: the cells of the negative group take the copy.
  const int copy = net.node_count;
  x.col(copy) = x.col(worst);
  int moved = 0;
  for (auto& nodes : net.cell_nodes)
    for (int a = 0; a < 8; ++a)
      if (nodes[static_cast<std::size_t>(a)] == worst && !(along(nodes, a, by_force) > 0.0)) {
        nodes[static_cast<std::size_t>(a)] = copy;
        ++moved;
      }
  if (moved == 0) return false;
  net.node_count = copy + 1;
  x.col(copy) = x.col(worst);
  v.col(copy) = v.col(worst);
  net.rest.col(copy) = net.rest.col(worst);
  net.constraint[static_cast<std::size_t>(copy)] = net.constraint[static_cast<std::size_t>(worst)];
  const double total_cells = m_cells[static_cast<std::size_t>(worst)];
  net.mass[static_cast<std::size_t>(copy)] = moved * net.cell_mass / 8.0;
  net.mass[static_cast<std::size_t>(worst)] = (total_cells - moved) * net.cell_mass / 8.0;
  m_opened[static_cast<std::size_t>(worst)] = m_opened[static_cast<std::size_t>(copy)] = 1;
  merge_springs_after_split(net, worst, copy);
  share_springs_after_split(net, copy);
  return true;
}

} // namespace kerf
