#pragma once
// Views between CHOLMOD's types and kerf's, over the same arrays (nothing copied; the viewed
// object must outlive the view): an Eigen compressed-column matrix as a cholmod_sparse, and a
// supernodal cholmod_factor's structure as a SupernodalStructure.

#include "realtime/springs/supernodal_cholesky.hpp"

#include <cholmod.h>

#include <Eigen/SparseCore>

#include <cstddef>

namespace kerf {

/// The matrix must stay compressed, with row indices sorted in each column. `stype` as CHOLMOD reads it: −1 the lower triangle of a symmetric matrix, 0 unsymmetric.
inline cholmod_sparse cholmod_view(Eigen::SparseMatrix<double, Eigen::ColMajor, int>& m, int stype) {
  cholmod_sparse s{};
  s.nrow = static_cast<std::size_t>(m.rows());
  s.ncol = static_cast<std::size_t>(m.cols());
  s.nzmax = static_cast<std::size_t>(m.nonZeros());
  s.p = m.outerIndexPtr();
  s.i = m.innerIndexPtr();
  s.x = m.valuePtr();
  s.stype = stype;
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

/// The supernodes, rows and value layout of a supernodal factor (CHOLMOD_INT); empty for a
/// simplicial one.
inline SupernodalStructure supernodal_structure(const cholmod_factor& f) noexcept {
  if (!f.is_super) return {};
  return {static_cast<int>(f.n), static_cast<int>(f.nsuper), static_cast<const int*>(f.super), static_cast<const int*>(f.pi),
          static_cast<const int*>(f.px), static_cast<const int*>(f.s)};
}

} // namespace kerf
