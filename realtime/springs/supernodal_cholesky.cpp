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

/// The left-looking traversal both phases share. For each supernode s in order: `start(s)`; then
/// `update(s, d, first, inside)` for every descendant d, whose rows [first, inside) (offsets into
/// d's rows) lie in s's columns and [first, end of d) are the rows from the first of them on;
/// then `finish(s)`. Each descendant is kept on the list of the next supernode its rows reach
/// (head / next; its next row in `position`). False, and the traversal stops, when `start` or
/// `finish` says false.
template <class Start, class Update, class Finish>
bool left_looking(const SupernodalStructure& L, const int* supernode_of, int* head, int* next, int* position, Start start,
                  Update update, Finish finish) {
  const auto link = [&](int d, int next_row) { // d onto the list of the supernode of `next_row`
    const int target = supernode_of[next_row];
    next[d] = head[target];
    head[target] = d;
  };
  std::fill(head, head + L.supernodes, -1);
  for (int s = 0; s < L.supernodes; ++s) {
    if (!start(s)) return false;
    const int k2 = L.super[s + 1];
    int d = head[s];
    head[s] = -1;
    while (d >= 0) {
      const int after = next[d];
      const int ndrow = L.row_start[d + 1] - L.row_start[d];
      const int* drows = L.rows + L.row_start[d];
      int inside = position[d];
      while (inside < ndrow && drows[inside] < k2) ++inside;
      update(s, d, position[d], inside);
      position[d] = inside;
      if (inside < ndrow) link(d, drows[inside]);
      d = after;
    }
    if (!finish(s)) return false;
    const int nscol = k2 - L.super[s];
    if (L.row_start[s + 1] - L.row_start[s] > nscol) {
      position[s] = nscol;
      link(s, L.rows[L.row_start[s] + nscol]);
    }
  }
  return true;
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
  left_looking(
      L, m_supernode_of.data(), m_head.data(), m_next.data(), m_position.data(), [](int) { return true; },
      [&](int, int d, int first, int inside) {
        const int ndrow = L.row_start[d + 1] - L.row_start[d];
        largest = std::max(largest, static_cast<std::size_t>(ndrow - first) * static_cast<std::size_t>(inside - first));
      },
      [](int) { return true; });
  m_update.assign(std::max<std::size_t>(largest, 1), 0.0);
}

bool SupernodalCholesky::factorize(const SupernodalStructure& L, const LowerCompressedColumns& a, double* lx) noexcept {
  m_failed_column = -1;
  if (m_supernode_of.size() != static_cast<std::size_t>(L.n) || m_head.size() != static_cast<std::size_t>(L.supernodes)) return false;
  int* map = m_map.data();
  int* relative = m_relative.data();
  double* update = m_update.data();
  static constexpr char lower = 'L', no = 'N', transposed = 'T', right = 'R';
  static constexpr double one = 1.0, zero = 0.0;

  // 1. L_s ← A(rows(s), cols(s)).
  const auto scatter_a = [&](int s) {
    const int k1 = L.super[s], k2 = L.super[s + 1];
    const int* srows = L.rows + L.row_start[s];
    const int nsrow = L.row_start[s + 1] - L.row_start[s];
    double* ls = lx + L.value_start[s];
    for (int k = 0; k < nsrow; ++k) map[srows[k]] = k;
    std::fill(ls, ls + static_cast<std::ptrdiff_t>(nsrow) * (k2 - k1), 0.0);
    for (int j = k1; j < k2; ++j) {
      double* column = ls + static_cast<std::ptrdiff_t>(j - k1) * nsrow;
      for (int p = a.column_start[j]; p < a.column_start[j + 1]; ++p) {
        const int i = a.row[p];
        const int k = map[i];
        if (i < j || k < 0 || k >= nsrow || srows[k] != i) return false; // not in L's pattern
        column[k] = a.value[p];
      }
    }
    return true;
  };
  // 2. L_s −= L_d L_dᵀ (restricted to rows(s) x cols(s)) for a descendant d.
  const auto subtract_descendant = [&](int s, int d, int p, int inside) {
    const int nsrow = L.row_start[s + 1] - L.row_start[s];
    double* ls = lx + L.value_start[s];
    const int ndcol = L.super[d + 1] - L.super[d];
    const int ndrow = L.row_start[d + 1] - L.row_start[d];
    const int* drows = L.rows + L.row_start[d];
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
  };
  // 3. L_ss ← chol(L_ss); L_bs ← L_bs L_ss⁻ᵀ.
  const auto factor_supernode = [&](int s) {
    const int k1 = L.super[s], nscol = L.super[s + 1] - k1;
    const int nsrow = L.row_start[s + 1] - L.row_start[s];
    double* ls = lx + L.value_start[s];
    int info = 0;
    dpotrf_(&lower, &nscol, ls, &nsrow, &info, 1);
    if (info != 0) { // info > 0: the leading minor of order info is not positive definite
      m_failed_column = info > 0 ? k1 + info - 1 : -1;
      return false;
    }
    if (nsrow > nscol) {
      const int below = nsrow - nscol;
      dtrsm_(&right, &lower, &transposed, &no, &below, &nscol, &one, ls, &nsrow, ls + nscol, &nsrow, 1, 1, 1, 1);
    }
    return true;
  };
  return left_looking(L, m_supernode_of.data(), m_head.data(), m_next.data(), m_position.data(), scatter_a,
                      subtract_descendant, factor_supernode);
}

} // namespace kerf
