#include "realtime/springs/network_system.hpp"

#include <algorithm>

namespace kerf {

void NetworkSystem::rebuild(const SpringNetwork& net) {
  // Free dofs in node order first.
  std::vector<int> natural(static_cast<std::size_t>(3 * net.node_capacity()), -1);
  int n = 0;
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (!(net.constraint[static_cast<std::size_t>(p)] & (1u << i))) natural[static_cast<std::size_t>(3 * p + i)] = n++;
  // Pattern of all cell couplings (both triangles) for the ordering.
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(net.cell_count()) * 576);
  for (const auto& nodes : net.cell_nodes)
    for (int a = 0; a < 24; ++a) {
      const int r = natural[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(a / 3)] + a % 3)];
      if (r < 0) continue;
      for (int b = 0; b < 24; ++b) {
        const int c = natural[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(b / 3)] + b % 3)];
        if (c >= 0) triplets.emplace_back(r, c, 1.0);
      }
    }
  Matrix full(n, n);
  full.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> new_to_old;
  Eigen::AMDOrdering<int> amd;
  amd(full, new_to_old);
  std::vector<int> old_to_new(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    old_to_new[static_cast<std::size_t>(new_to_old.size() > 0 ? new_to_old.indices()[k] : k)] = k;
  m_dof_of.assign(natural.size(), -1);
  for (std::size_t k = 0; k < natural.size(); ++k)
    if (natural[k] >= 0) m_dof_of[k] = old_to_new[static_cast<std::size_t>(natural[k])];

  // Upper-triangular pattern in the new order.
  triplets.clear();
  for (const auto& nodes : net.cell_nodes)
    for (int a = 0; a < 24; ++a) {
      const int r = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(a / 3)] + a % 3)];
      if (r < 0) continue;
      for (int b = 0; b < 24; ++b) {
        const int c = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(b / 3)] + b % 3)];
        if (c >= r) triplets.emplace_back(r, c, 1.0);
      }
    }
  m_matrix.resize(n, n);
  m_matrix.setFromTriplets(triplets.begin(), triplets.end());
  m_matrix.makeCompressed();
  const auto index_of = [this](int r, int c) {
    const int* rows = m_matrix.innerIndexPtr();
    const int begin = m_matrix.outerIndexPtr()[c], end = m_matrix.outerIndexPtr()[c + 1];
    return static_cast<int>(std::lower_bound(rows + begin, rows + end, r) - rows);
  };
  m_entry.assign(static_cast<std::size_t>(net.cell_count()) * 576, -1);
  for (int cell = 0; cell < net.cell_count(); ++cell) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
    for (int a = 0; a < 24; ++a) {
      const int r = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(a / 3)] + a % 3)];
      if (r < 0) continue;
      for (int b = 0; b < 24; ++b) {
        const int c = m_dof_of[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(b / 3)] + b % 3)];
        if (c >= r) m_entry[static_cast<std::size_t>(cell) * 576 + static_cast<std::size_t>(24 * a + b)] = index_of(r, c);
      }
    }
  }
  m_diagonal.assign(static_cast<std::size_t>(n), -1);
  for (int k = 0; k < n; ++k) m_diagonal[static_cast<std::size_t>(k)] = index_of(k, k);
  m_ldlt.analyzePattern(m_matrix);
  m_factorized = false;
}

void NetworkSystem::assemble(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight,
                             double stiffness_weight) noexcept {
  double* values = m_matrix.valuePtr();
  std::fill(values, values + m_matrix.nonZeros(), 0.0);
  Eigen::Matrix<double, 3, 8> xc;
  Eigen::Matrix<double, 24, 24> K;
  for (int cell = 0; cell < net.cell_count(); ++cell) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
    for (int a = 0; a < 8; ++a) xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]);
    cell_stiffness_matrix(net, cell, xc, K);
    const int* entry = m_entry.data() + static_cast<std::size_t>(cell) * 576;
    for (int a = 0; a < 24; ++a)
      for (int b = 0; b < 24; ++b)
        if (const int e = entry[24 * a + b]; e >= 0) values[e] += stiffness_weight * K(a, b);
  }
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (const int d = m_dof_of[static_cast<std::size_t>(3 * p + i)]; d >= 0)
        values[m_diagonal[static_cast<std::size_t>(d)]] += mass_weight * net.mass[static_cast<std::size_t>(p)];
}

bool NetworkSystem::factorize() noexcept {
  m_ldlt.factorize_in_place(m_matrix);
  m_factorized = m_ldlt.info() == Eigen::Success;
  return m_factorized;
}

void NetworkSystem::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) const noexcept {
  out = rhs;
  // L D Lᵀ out = rhs (no permutation: the matrix is assembled in the factor's order)
  m_ldlt.matrixL().solveInPlace(out);
  out.array() /= m_ldlt.diagonal().array();
  m_ldlt.matrixU().solveInPlace(out);
}

} // namespace kerf
