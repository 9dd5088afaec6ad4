#pragma once
// CHOLMOD's view of an Eigen compressed-column matrix: a cholmod_sparse header over the matrix's
// own arrays (nothing copied; the matrix must outlive the view and stay compressed, with row
// indices sorted in each column).

#include <cholmod.h>

#include <Eigen/SparseCore>

#include <cstddef>

namespace kerf {

/// `stype` as CHOLMOD reads it: −1 the lower triangle of a symmetric matrix, 0 unsymmetric.
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

} // namespace kerf
