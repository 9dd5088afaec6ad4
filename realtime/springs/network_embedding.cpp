#include "realtime/springs/network_embedding.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

namespace {

/// Trilinear weight of local corner a at ξ.
double trilinear_weight(int a, const Eigen::Vector3d& xi) {
  double w = 1.0;
  for (int i = 0; i < 3; ++i) w *= ((a >> i) & 1) ? xi[i] : 1.0 - xi[i];
  return w;
}

Eigen::Vector3d trilinear(const SpringNetwork& net, const Eigen::Matrix3Xd& x, int cell, const Eigen::Vector3d& xi) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
  for (int a = 0; a < 8; ++a) p += trilinear_weight(a, xi) * x.col(nodes[static_cast<std::size_t>(a)]);
  return p;
}

Eigen::Vector3d coons(const SpringNetwork& net, const Eigen::Matrix3Xd& x, int cell, const Eigen::Vector3d& xi) {
  const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
  const Eigen::Vector3i& g = net.cell_index[static_cast<std::size_t>(cell)];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int d = 0; d < 3; ++d) {
    const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
    const int before = net.cell_at_index(g - Eigen::Vector3i::Unit(d));
    const int after = net.cell_at_index(g + Eigen::Vector3i::Unit(d));
    const double t = xi[d];
    // Cubic Hermite basis.
    const double h00 = 2 * t * t * t - 3 * t * t + 1, h10 = t * t * t - 2 * t * t + t;
    const double h01 = -2 * t * t * t + 3 * t * t, h11 = t * t * t - t * t;
    for (int b1 = 0; b1 < 2; ++b1)
      for (int b2 = 0; b2 < 2; ++b2) {
        const int a0 = (b1 << d1) | (b2 << d2), a1 = a0 | (1 << d);
        const int n0 = nodes[static_cast<std::size_t>(a0)], n1 = nodes[static_cast<std::size_t>(a1)];
        const Eigen::Vector3d P0 = x.col(n0), P1 = x.col(n1);
        // End tangents (per unit ξ): central differences over the neighbour nodes along the
        // edge when the neighbouring cell shares the end node, else the chord.
        Eigen::Vector3d T0 = P1 - P0, T1 = P1 - P0;
        if (before >= 0) {
          const auto& nb = net.cell_nodes[static_cast<std::size_t>(before)];
          if (nb[static_cast<std::size_t>(a1)] == n0) T0 = 0.5 * (P1 - x.col(nb[static_cast<std::size_t>(a0)]));
        }
        if (after >= 0) {
          const auto& na = net.cell_nodes[static_cast<std::size_t>(after)];
          if (na[static_cast<std::size_t>(a0)] == n1) T1 = 0.5 * (x.col(na[static_cast<std::size_t>(a1)]) - P0);
        }
        const Eigen::Vector3d edge = h00 * P0 + h10 * T0 + h01 * P1 + h11 * T1;
        const double blend = (b1 ? xi[d1] : 1.0 - xi[d1]) * (b2 ? xi[d2] : 1.0 - xi[d2]);
        sum += blend * edge;
      }
  }
  // x = Σ_e B_e E_e − 2 Σ_a N_a x_a
  return sum - 2.0 * trilinear(net, x, cell, xi);
}

} // namespace

NetworkEmbedding::NetworkEmbedding(const SpringNetwork& net, const Eigen::MatrixXd& points, EmbeddingScheme scheme,
                                   const std::vector<int>* host_cells)
    : m_scheme(scheme), m_rest(points) {
  if (points.cols() != 3) throw std::invalid_argument("NetworkEmbedding: points must be #P by 3");
  if (host_cells && host_cells->size() != static_cast<std::size_t>(points.rows()))
    throw std::invalid_argument("NetworkEmbedding: one host cell per point expected");
  const double h = net.block.cell_size;
  const double eps = 1e-9;
  m_cell.assign(static_cast<std::size_t>(points.rows()), -1);
  m_local.assign(static_cast<std::size_t>(points.rows()), Eigen::Vector3d::Zero());
  for (int p = 0; p < points.rows(); ++p) {
    const Eigen::Vector3d q = (points.row(p).transpose() - net.block.origin) / h;
    int host = -1;
    if (host_cells) {
      host = (*host_cells)[static_cast<std::size_t>(p)];
    } else {
      const Eigen::Vector3i base = q.array().floor().cast<int>();
      // A point on a cell face, edge or corner may lie in a neighbour cell: try them all.
      for (int k = 0; k < 8 && host < 0; ++k) {
        Eigen::Vector3i g = base;
        bool valid = true;
        for (int i = 0; i < 3; ++i)
          if ((k >> i) & 1) {
            if (q[i] - base[i] < eps) g[i] -= 1;
            else valid = false;
          }
        if (valid) host = net.cell_at_index(g);
      }
    }
    if (host < 0) continue;
    const Eigen::Vector3d xi = q - net.cell_index[static_cast<std::size_t>(host)].cast<double>();
    if ((xi.array() < -eps).any() || (xi.array() > 1.0 + eps).any()) continue;
    m_cell[static_cast<std::size_t>(p)] = host;
    m_local[static_cast<std::size_t>(p)] = xi.cwiseMax(0.0).cwiseMin(1.0);
  }
}

int NetworkEmbedding::embedded_count() const {
  return static_cast<int>(std::count_if(m_cell.begin(), m_cell.end(), [](int c) { return c >= 0; }));
}

void NetworkEmbedding::apply(const SpringNetwork& net, const Eigen::Matrix3Xd& x, Eigen::MatrixXd& out) const noexcept {
  for (int p = 0; p < m_rest.rows(); ++p) {
    const int c = m_cell[static_cast<std::size_t>(p)];
    if (c < 0) {
      out.row(p) = m_rest.row(p);
      continue;
    }
    const Eigen::Vector3d& xi = m_local[static_cast<std::size_t>(p)];
    out.row(p) = (m_scheme == EmbeddingScheme::trilinear ? trilinear(net, x, c, xi) : coons(net, x, c, xi)).transpose();
  }
}

} // namespace kerf
