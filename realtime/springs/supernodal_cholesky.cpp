#include "realtime/springs/supernodal_cholesky.hpp"

#include <algorithm>
#include <cstddef>

// BLAS and LAPACK (Debian's libblas3 / liblapack3 alternatives: OpenBLAS on this machine), with
// the Fortran calling convention: every argument by address, 32-bit integers (LP64), and one
// hidden length per character argument, last (gfortran's ABI; C implementations ignore them).
extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc, std::size_t, std::size_t);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c, const int* ldc,
            std::size_t, std::size_t);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, std::size_t, std::size_t,
            std::size_t, std::size_t);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
}

namespace kerf {

namespace {

/// Puts descendant d on the list of the supernode that its row `next_row` belongs to.
inline void link_descendant(int d, int next_row, const int* supernode_of, int* head, int* next) noexcept {
  const int target = supernode_of[next_row];
  next[d] = head[target];
  head[target] = d;
}

} // namespace

void SupernodalCholesky::analyse(const SupernodalStructure& L) {
  m_supernode_of.assign(static_cast<std::size_t>(L.n), -1);
  for (int s = 0; s < L.supernodes; ++s)
    for (int j = L.super[s]; j < L.super[s + 1]; ++j) m_supernode_of[static_cast<std::size_t>(j)] = s;
  m_map.assign(static_cast<std::size_t>(L.n), -1);
  int tallest = 0;
  for (int s = 0; s < L.supernodes; ++s) tallest = std::max(tallest, L.row_start[s + 1] - L.row_start[s]);
  m_relative.assign(static_cast<std::size_t>(tallest), 0);
  m_head.assign(static_cast<std::size_t>(L.supernodes), -1);
  m_next.assign(static_cast<std::size_t>(L.supernodes), -1);
  m_position.assign(static_cast<std::size_t>(L.supernodes), 0);

  // The largest update block C (ndrow2 x ndrow1) over every (descendant, supernode) pair: the
  // numeric phase's traversal without the numbers.
  std::size_t largest = 0;
  for (int s = 0; s < L.supernodes; ++s) {
    const int k2 = L.super[s + 1];
    int d = m_head[static_cast<std::size_t>(s)];
    m_head[static_cast<std::size_t>(s)] = -1;
    while (d >= 0) {
      const int after = m_next[static_cast<std::size_t>(d)];
      const int first = L.row_start[d] + m_position[static_cast<std::size_t>(d)], end = L.row_start[d + 1];
      int inside = first;
      while (inside < end && L.rows[inside] < k2) ++inside;
      largest = std::max(largest, static_cast<std::size_t>(end - first) * static_cast<std::size_t>(inside - first));
      m_position[static_cast<std::size_t>(d)] = inside - L.row_start[d];
      if (inside < end) link_descendant(d, L.rows[inside], m_supernode_of.data(), m_head.data(), m_next.data());
      d = after;
    }
    const int nscol = k2 - L.super[s], nsrow = L.row_start[s + 1] - L.row_start[s];
    if (nsrow > nscol) {
      m_position[static_cast<std::size_t>(s)] = nscol;
      link_descendant(s, L.rows[L.row_start[s] + nscol], m_supernode_of.data(), m_head.data(), m_next.data());
    }
  }
  m_update.assign(std::max<std::size_t>(largest, 1), 0.0);
}

bool SupernodalCholesky::factorize(const SupernodalStructure& L, const LowerCompressedColumns& a, double* lx) noexcept {
  m_failed_column = -1;
  if (m_supernode_of.size() != static_cast<std::size_t>(L.n) || m_head.size() != static_cast<std::size_t>(L.supernodes)) return false;
  std::fill(m_head.begin(), m_head.end(), -1);
  int* map = m_map.data();
  int* relative = m_relative.data();
  double* update = m_update.data();
  static constexpr char lower = 'L', no = 'N', transposed = 'T', right = 'R';
  static constexpr double one = 1.0, zero = 0.0;

  for (int s = 0; s < L.supernodes; ++s) {
    const int k1 = L.super[s], k2 = L.super[s + 1], nscol = k2 - k1;
    const int* srows = L.rows + L.row_start[s];
    const int nsrow = L.row_start[s + 1] - L.row_start[s];
    double* ls = lx + L.value_start[s];
    for (int k = 0; k < nsrow; ++k) map[srows[k]] = k;

    // 1. L_s ← A(rows(s), cols(s)).
    std::fill(ls, ls + static_cast<std::ptrdiff_t>(nsrow) * nscol, 0.0);
    for (int j = k1; j < k2; ++j) {
      double* column = ls + static_cast<std::ptrdiff_t>(j - k1) * nsrow;
      for (int p = a.column_start[j]; p < a.column_start[j + 1]; ++p) {
        const int i = a.row[p];
        const int k = map[i];
        if (i < j || k < 0 || k >= nsrow || srows[k] != i) return false; // not in L's pattern
        column[k] = a.value[p];
      }
    }

    // 2. L_s −= L_d L_dᵀ (restricted to rows(s) x cols(s)) for every descendant d.
    int d = m_head[static_cast<std::size_t>(s)];
    m_head[static_cast<std::size_t>(s)] = -1;
    while (d >= 0) {
      const int after = m_next[static_cast<std::size_t>(d)];
      const int ndcol = L.super[d + 1] - L.super[d];
      const int ndrow = L.row_start[d + 1] - L.row_start[d];
      const int* drows = L.rows + L.row_start[d];
      const int p = m_position[static_cast<std::size_t>(d)];
      int inside = p;
      while (inside < ndrow && drows[inside] < k2) ++inside;
      const int ndrow1 = inside - p;   // d's rows in cols(s): C's columns
      const int ndrow2 = ndrow - p;    // d's rows from the first in cols(s) on: C's rows
      const int ndrow3 = ndrow2 - ndrow1;
      const double* ld = lx + L.value_start[d] + p;
      // C(0:ndrow1, 0:ndrow1) = L1 L1ᵀ (lower triangle), C(ndrow1:ndrow2, :) = L2 L1ᵀ.
      dsyrk_(&lower, &no, &ndrow1, &ndcol, &one, ld, &ndrow, &zero, update, &ndrow2, 1, 1);
      if (ndrow3 > 0) dgemm_(&no, &transposed, &ndrow3, &ndrow1, &ndcol, &one, ld + ndrow1, &ndrow, ld, &ndrow, &zero, update + ndrow1, &ndrow2, 1, 1);
      for (int i = 0; i < ndrow2; ++i) relative[i] = map[drows[p + i]];
      for (int j = 0; j < ndrow1; ++j) {
        double* column = ls + static_cast<std::ptrdiff_t>(relative[j]) * nsrow;
        const double* c = update + static_cast<std::ptrdiff_t>(j) * ndrow2;
        for (int i = j; i < ndrow2; ++i) column[relative[i]] -= c[i];
      }
      m_position[static_cast<std::size_t>(d)] = inside;
      if (inside < ndrow) link_descendant(d, drows[inside], m_supernode_of.data(), m_head.data(), m_next.data());
      d = after;
    }

    // 3. L_ss ← chol(L_ss); L_bs ← L_bs L_ss⁻ᵀ.
    int info = 0;
    dpotrf_(&lower, &nscol, ls, &nsrow, &info, 1);
    if (info != 0) { // info > 0: the leading minor of order info is not positive definite
      m_failed_column = info > 0 ? k1 + info - 1 : -1;
      return false;
    }
    if (nsrow > nscol) {
      const int below = nsrow - nscol;
      dtrsm_(&right, &lower, &transposed, &no, &below, &nscol, &one, ls, &nsrow, ls + nscol, &nsrow, 1, 1, 1, 1);
      m_position[static_cast<std::size_t>(s)] = nscol;
      link_descendant(s, srows[nscol], m_supernode_of.data(), m_head.data(), m_next.data());
    }
  }
  return true;
}

} // namespace kerf
