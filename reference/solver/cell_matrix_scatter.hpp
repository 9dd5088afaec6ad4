#pragma once
// Adding one cell's matrix and right-hand side to the serial system under Dirichlet constraints
// (used by assemble_system.cpp; the distributed system keeps deal.II's distribute_local_to_global).
//
// The serial solver's constraints are Dirichlet conditions alone: every constrained DOF i has the
// prescribed value u_i = g_i and depends on no other DOF (system_setup.cpp, dirichlet_constraints).
// For such constraints AffineConstraints::distribute_local_to_global(K_c, r_c, dofs, K, r)
// (deal.II 9.4, use_inhomogeneities_for_rhs = false) adds
//
//   free i, free j:   K_ij += K_c,ij
//   free i:           r_i  += r_c,i − Σ_{j constrained} K_c,ij g_j
//   constrained i:    K_ii += |K_c,ii|, or the mean |K_c,kk| of the cell when K_c,ii = 0
//                     (the cell's l1 norm / n when that is 0 too, else 1); r_i unchanged
//
// so the constrained rows and columns decouple and constraints.distribute() sets u_i = g_i after
// the solve. This class does the same additions, each to an entry whose place in the matrix's
// value array was looked up once per cell (SparsityPattern::operator()), instead of sorting the
// cell's rows and searching each global row at every assembly: on potato_rect_cut's P1 cells that
// search was a seventh of the reference's CPU time (docs/reference.md, "Where the time goes").

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace kerf::reference {

class CellMatrixScatter {
public:
  /// The places of every active cell's n × n entries in `pattern` (built without the constrained
  /// rows' and columns' off-diagonal entries, as make_sparsity_pattern with the constraints does).
  void build(const dealii::DoFHandler<3>& dof, const dealii::SparsityPattern& pattern) {
    m_n = dof.get_fe().n_dofs_per_cell();
    m_position.assign(dof.get_triangulation().n_active_cells() * m_n * m_n, none);
    if (pattern.n_nonzero_elements() >= none)
      throw std::length_error("CellMatrixScatter: more matrix entries than 32-bit places can index");
    std::vector<dealii::types::global_dof_index> dofs(m_n);
    std::vector<std::pair<dealii::types::global_dof_index, unsigned>> by_dof(m_n); // (DOF, local index), sorted
    for (const auto& cell : dof.active_cell_iterators()) {
      cell->get_dof_indices(dofs);
      for (unsigned j = 0; j < m_n; ++j) by_dof[j] = {dofs[j], j};
      std::sort(by_dof.begin(), by_dof.end());
      std::uint32_t* p = &m_position[cell->active_cell_index() * m_n * m_n];
      // Row i of the pattern, walked beside the cell's sorted DOFs (a row holds its diagonal
      // first, then its other columns in increasing order).
      for (unsigned i = 0; i < m_n; ++i) {
        std::size_t k = 0;
        for (auto e = pattern.begin(dofs[i]); e != pattern.end(dofs[i]); ++e) {
          const auto column = e->column();
          if (column == dofs[i]) {
            p[i * m_n + i] = static_cast<std::uint32_t>(e->global_index());
            continue;
          }
          while (k < m_n && by_dof[k].first < column) ++k;
          if (k < m_n && by_dof[k].first == column) p[i * m_n + by_dof[k].second] = static_cast<std::uint32_t>(e->global_index());
        }
      }
    }
  }

  /// The start of K's value array, in the order of its sparsity pattern's entries: the first
  /// row's diagonal, which a square pattern stores first in its row (checked on the last row).
  [[nodiscard]] static double* values(dealii::SparseMatrix<double>& K) {
    double* base = &K.diag_element(0);
    const auto last = K.m() - 1;
    if (K.get_sparsity_pattern()(0, 0) != 0 || &K.diag_element(last) != base + K.get_sparsity_pattern()(last, last))
      throw std::logic_error("CellMatrixScatter: the matrix's values are not stored in its pattern's order");
    return base;
  }

  /// K_c and r_c of the active cell `cell` (its DOFs `dofs`) added to K (value array `values`) and r.
  void add(std::size_t cell, const dealii::FullMatrix<double>& Kc, const dealii::Vector<double>& rc,
           const std::vector<dealii::types::global_dof_index>& dofs, const dealii::AffineConstraints<double>& constraints,
           double* values, dealii::Vector<double>& r) const {
    const std::uint32_t* p = &m_position[cell * m_n * m_n];
    bool any_constrained = false;
    for (unsigned j = 0; j < m_n; ++j) any_constrained = any_constrained || constraints.is_constrained(dofs[j]);
    if (!any_constrained) {
      for (unsigned i = 0; i < m_n; ++i) {
        for (unsigned j = 0; j < m_n; ++j) values[p[i * m_n + j]] += Kc(i, j);
        r(dofs[i]) += rc(i);
      }
      return;
    }
    for (unsigned i = 0; i < m_n; ++i) {
      if (constraints.is_constrained(dofs[i])) {
        const double diagonal = std::abs(Kc(i, i));
        values[p[i * m_n + i]] += diagonal != 0.0 ? diagonal : mean_diagonal(Kc);
        continue;
      }
      double ri = rc(i);
      for (unsigned j = 0; j < m_n; ++j) {
        if (constraints.is_constrained(dofs[j]))
          ri -= Kc(i, j) * constraints.get_inhomogeneity(dofs[j]);
        else
          values[p[i * m_n + j]] += Kc(i, j);
      }
      r(dofs[i]) += ri;
    }
  }

private:
  static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
  /// deal.II's diagonal for a constrained row whose cell diagonal entry is zero.
  [[nodiscard]] static double mean_diagonal(const dealii::FullMatrix<double>& Kc) {
    double mean = 0.0;
    for (unsigned k = 0; k < Kc.m(); ++k) mean += std::abs(Kc(k, k));
    mean /= static_cast<double>(Kc.m());
    if (mean == 0.0) mean = Kc.l1_norm() / static_cast<double>(Kc.m());
    return mean == 0.0 ? 1.0 : mean;
  }
  unsigned m_n = 0;
  std::vector<std::uint32_t> m_position; ///< cell × n × n: the entry's place in the value array, or none
};

} // namespace kerf::reference
