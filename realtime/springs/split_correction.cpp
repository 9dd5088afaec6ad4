#include "realtime/springs/split_correction.hpp"

#include <algorithm>
#include <cmath>

namespace kerf {

namespace {
constexpr int padding = 16; // the forward substitution's vectors have room for one more float vector
} // namespace

void SplitCorrection::reserve(int dofs) {
  m_capacity = m_dofs = dofs;
  m_f.assign(static_cast<std::size_t>(max_columns) * static_cast<std::size_t>(dofs + padding), 0.0f);
  m_ranges.assign(static_cast<std::size_t>(max_splits) * 2 * static_cast<std::size_t>(dofs + 1), 0);
  m_y_single.assign(static_cast<std::size_t>(dofs + padding), 0.0f);
  m_g.setZero(max_columns, max_columns);
  m_c.setZero(max_columns, max_columns);
  m_h.setZero(max_columns, max_columns);
  m_pivot.assign(max_columns, 0);
  m_u.setZero(max_columns);
  m_t.setZero(max_columns);
  clear();
}

void SplitCorrection::column_of_w(int split, int j, float* v) const noexcept {
  std::fill(v, v + m_dofs + padding, 0.0f);
  const Split& s = m_split[split];
  if (j < 2 * s.r) { // U_S
    v[s.s[j]] = 1.0f;
    return;
  }
  // V = U_N Bᵀ: column i = row i of B on N
  const int i = j - 2 * s.r;
  for (int k = 0; k < s.neighbours; ++k) v[s.n[k]] = static_cast<float>(s.b[i][k]);
}

bool SplitCorrection::add(NetworkSystem& system, const SpringNetwork& net, const Eigen::Matrix3Xd& x, int original, int copy,
                          double mass_before, double mass_weight, double stiffness_weight, CellTangent tangent,
                          const NodePair* later, int later_count) noexcept {
  if (m_splits == 0) m_dofs = system.dof_count(); // a system of its own numbering since `clear`
  if (full() || m_dofs != system.dof_count() || m_dofs > m_capacity) return false;
  const std::vector<int>& dof = system.dof_of();
  Split& s = m_split[m_splits];
  s = Split{};
  int axis[3];
  for (int i = 0; i < 3; ++i)
    if (const int d = dof[static_cast<std::size_t>(3 * original + i)]; d >= 0) axis[s.r++] = i;
  if (s.r == 0) return true; // a fixed node: no unknown changes
  for (int k = 0; k < s.r; ++k) {
    s.s[k] = dof[static_cast<std::size_t>(3 * original + axis[k])];
    s.s[s.r + k] = dof[static_cast<std::size_t>(3 * copy + axis[k])];
    if (s.s[k] < 0 || s.s[s.r + k] < 0) return false;
  }
  // Σ over the moved cells (the copy's) of K_c(p, p) and K_c(p, q).
  Eigen::Matrix3d kpp = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 8> xc;
  Eigen::Matrix<double, 24, 24> K;
  for (int cell = 0; cell < net.cell_count(); ++cell) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(cell)];
    const int a = static_cast<int>(std::find(nodes.begin(), nodes.end(), copy) - nodes.begin());
    if (a == 8) continue;
    for (int b = 0; b < 8; ++b) xc.col(b) = x.col(nodes[static_cast<std::size_t>(b)]);
    cell_stiffness_matrix(net, cell, xc, K, tangent);
    kpp += stiffness_weight * K.block<3, 3>(3 * a, 3 * a);
    for (int b = 0; b < 8; ++b) {
      if (b == a) continue;
      // The corner as it was at this split: a later split's copy is still its original.
      int node = nodes[static_cast<std::size_t>(b)];
      for (int k = 0; k < later_count; ++k)
        if (later[k].copy == node) node = later[k].original;
      for (int i = 0; i < 3; ++i) {
        const int q = dof[static_cast<std::size_t>(3 * node + i)];
        if (q < 0) continue;
        int k = static_cast<int>(std::find(s.n, s.n + s.neighbours, q) - s.n);
        if (k == s.neighbours) {
          if (s.neighbours == 3 * max_neighbours) return false;
          s.n[s.neighbours++] = q;
        }
        for (int row = 0; row < s.r; ++row) s.b[row][k] += stiffness_weight * K(3 * a + axis[row], 3 * b + i);
      }
    }
  }
  // D: the change of the S x S block.
  const double copy_mass = net.mass[static_cast<std::size_t>(copy)];
  const double lost_mass = mass_before - net.mass[static_cast<std::size_t>(original)];
  for (int i = 0; i < s.r; ++i)
    for (int j = 0; j < s.r; ++j) {
      const double k = kpp(axis[i], axis[j]);
      s.d[i][j] = -k - (i == j ? mass_weight * lost_mass : 0.0);
      s.d[s.r + i][s.r + j] = k + (i == j ? mass_weight * copy_mass - system.diagonal(s.s[s.r + i]) : 0.0);
    }
  // F's new columns, L⁻¹ W_new, and the supernodes they reach.
  const int first = m_columns, count = 3 * s.r;
  const auto stride = static_cast<std::ptrdiff_t>(m_dofs + padding);
  for (int j = 0; j < count; ++j) {
    float* f = m_f.data() + (first + j) * stride;
    column_of_w(m_splits, j, f);
    if (!system.forward_solve_in_place(f)) return false; // a double-precision system: no single-precision blocks
  }
  const auto ranges_of = [this](int split) { return m_ranges.data() + static_cast<std::ptrdiff_t>(split) * 2 * (m_dofs + 1); };
  int* ranges = ranges_of(m_splits);
  int& range_count = m_range_count[m_splits];
  range_count = 0;
  for (int sn = 0; sn < system.supernode_count(); ++sn) {
    const int begin = system.supernode_start(sn), end = system.supernode_start(sn + 1);
    bool reached = false;
    for (int j = 0; j < count && !reached; ++j) {
      const float* f = m_f.data() + (first + j) * stride;
      reached = std::any_of(f + begin, f + end, [](float v) { return v != 0.0f; });
    }
    if (!reached) continue;
    if (range_count > 0 && ranges[2 * range_count - 1] == begin) {
      ranges[2 * range_count - 1] = end;
    } else {
      ranges[2 * range_count] = begin;
      ranges[2 * range_count + 1] = end;
      ++range_count;
    }
  }
  // The new rows of G = Fᵀ F, over the ranges both splits' columns reach.
  for (int other = 0, column0 = 0; other <= m_splits; column0 += 3 * m_split[other].r, ++other) {
    const int* theirs = ranges_of(other);
    const int their_columns = 3 * m_split[other].r;
    for (int j = first; j < first + count; ++j) {
      const float* fj = m_f.data() + j * stride;
      for (int i = column0; i < column0 + their_columns && i <= j; ++i) {
        const float* fi = m_f.data() + i * stride;
        double dot = 0.0;
        for (int a = 0, b = 0; a < range_count && b < m_range_count[other];) {
          const int lo = std::max(ranges[2 * a], theirs[2 * b]), hi = std::min(ranges[2 * a + 1], theirs[2 * b + 1]);
          float partial = 0.0f;
          for (int k = lo; k < hi; ++k) partial += fi[k] * fj[k];
          dot += partial;
          if (ranges[2 * a + 1] < theirs[2 * b + 1]) ++a;
          else ++b;
        }
        m_g(i, j) = m_g(j, i) = dot;
      }
    }
  }
  // C's new block: [[D, J], [Jᵀ, 0]], J = [−I; I].
  const int m = first + count;
  m_c.block(first, 0, count, first).setZero();
  m_c.block(0, first, first, count).setZero();
  m_c.block(first, first, count, count).setZero();
  for (int i = 0; i < 2 * s.r; ++i)
    for (int j = 0; j < 2 * s.r; ++j) m_c(first + i, first + j) = s.d[i][j];
  for (int k = 0; k < s.r; ++k) {
    m_c(first + k, first + 2 * s.r + k) = m_c(first + 2 * s.r + k, first + k) = -1.0;
    m_c(first + s.r + k, first + 2 * s.r + k) = m_c(first + 2 * s.r + k, first + s.r + k) = 1.0;
  }
  if (!factor_h(m)) {
    // Singular with this split: left out, and H of the splits before it factorised again (the
    // attempt overwrote it in place, and later solves read it).
    if (first > 0 && !factor_h(first)) clear();
    return false;
  }
  m_columns = m;
  ++m_splits;
  return true;
}

bool SplitCorrection::factor_h(int m) noexcept {
  // H = I + C G, C block diagonal (a 3r x 3r block per split): row block by row block.
  for (int split = 0, b0 = 0; b0 < m; ++split) {
    const int b1 = b0 + 3 * m_split[split].r;
    for (int r = b0; r < b1; ++r)
      for (int c = 0; c < m; ++c) {
        double sum = r == c ? 1.0 : 0.0;
        for (int k = b0; k < b1; ++k) sum += m_c(r, k) * m_g(k, c);
        m_h(r, c) = sum;
      }
    b0 = b1;
  }
  double* a = m_h.data();
  const Eigen::Index lda = m_h.rows();
  const auto at = [a, lda](int r, int c) -> double& { return a[r + c * lda]; };
  for (int k = 0; k < m; ++k) {
    int p = k;
    for (int r = k + 1; r < m; ++r)
      if (std::abs(at(r, k)) > std::abs(at(p, k))) p = r;
    m_pivot[static_cast<std::size_t>(k)] = p;
    if (!(std::abs(at(p, k)) > 0.0) || !std::isfinite(at(p, k))) return false;
    if (p != k)
      for (int c = 0; c < m; ++c) std::swap(at(k, c), at(p, c));
    const double inverse = 1.0 / at(k, k);
    for (int r = k + 1; r < m; ++r) at(r, k) *= inverse;
    for (int c = k + 1; c < m; ++c) {
      const double akc = at(k, c);
      if (akc != 0.0)
        for (int r = k + 1; r < m; ++r) at(r, c) -= at(r, k) * akc;
    }
  }
  return true;
}

void SplitCorrection::solve_h(double* x) const noexcept {
  const int m = m_columns;
  const double* a = m_h.data();
  const Eigen::Index lda = m_h.rows();
  for (int k = 0; k < m; ++k) std::swap(x[k], x[m_pivot[static_cast<std::size_t>(k)]]);
  for (int c = 0; c < m; ++c)
    for (int r = c + 1; r < m; ++r) x[r] -= a[r + c * lda] * x[c];
  for (int c = m - 1; c >= 0; --c) {
    x[c] /= a[c + c * lda];
    for (int r = 0; r < c; ++r) x[r] -= a[r + c * lda] * x[c];
  }
}

void SplitCorrection::solve(NetworkSystem& system, const Eigen::VectorXd& rhs, Eigen::VectorXd& out) noexcept {
  if (m_columns == 0) {
    system.solve(rhs, out);
    return;
  }
  // With P = L Lᵀ and F = L⁻¹ W: Wᵀ P⁻¹ b = Fᵀ (L⁻¹ b) and P⁻¹ W t = L⁻ᵀ (F t), so
  //   (P + W C Wᵀ)⁻¹ b = L⁻ᵀ (y − F t),  y = L⁻¹ b,  t = H⁻¹ C Fᵀ y:
  // one forward and one backward substitution, F's columns read over the supernodes they reach
  // (a split's F is zero elsewhere). F exists only for a single-precision system (`add`).
  const auto stride = static_cast<std::ptrdiff_t>(m_dofs + padding);
  float* y = m_y_single.data();
  for (int k = 0; k < m_dofs; ++k) y[k] = static_cast<float>(rhs[k]);
  system.forward_solve_in_place(y);
  Eigen::VectorXd& u = m_u;
  for (int split = 0, j = 0; split < m_splits; ++split) {
    const int* ranges = m_ranges.data() + static_cast<std::ptrdiff_t>(split) * 2 * (m_dofs + 1);
    for (int c = 0; c < 3 * m_split[split].r; ++c, ++j) {
      const float* f = m_f.data() + j * stride;
      double dot = 0.0;
      for (int a = 0; a < m_range_count[split]; ++a) {
        float partial = 0.0f;
        for (int k = ranges[2 * a]; k < ranges[2 * a + 1]; ++k) partial += f[k] * y[k];
        dot += partial;
      }
      u[j] = dot;
    }
  }
  Eigen::VectorXd& t = m_t;
  for (int split = 0, b0 = 0; b0 < m_columns; ++split) {
    const int b1 = b0 + 3 * m_split[split].r;
    for (int r = b0; r < b1; ++r) {
      double sum = 0.0;
      for (int k = b0; k < b1; ++k) sum += m_c(r, k) * u[k];
      t[r] = sum;
    }
    b0 = b1;
  }
  solve_h(t.data());
  for (int split = 0, j = 0; split < m_splits; ++split) {
    const int* ranges = m_ranges.data() + static_cast<std::ptrdiff_t>(split) * 2 * (m_dofs + 1);
    for (int c = 0; c < 3 * m_split[split].r; ++c, ++j) {
      const float* f = m_f.data() + j * stride;
      const auto tj = static_cast<float>(t[j]);
      for (int a = 0; a < m_range_count[split]; ++a)
        for (int k = ranges[2 * a]; k < ranges[2 * a + 1]; ++k) y[k] -= f[k] * tj;
    }
  }
  system.backward_solve_in_place(y);
  for (int k = 0; k < m_dofs; ++k) out[k] = static_cast<double>(y[k]);
}

} // namespace kerf
