#pragma once
// SupernodalCholesky: the numeric phase of a left-looking supernodal Cholesky factorisation
// A = L Lᵀ, on a symbolic structure found elsewhere (CHOLMOD's analysis, in NetworkSystem).
//
// The algorithm is the one of Ng & Peyton ("Block sparse Cholesky algorithms on advanced
// uniprocessor computers", SIAM J. Sci. Comput. 14(5), 1993) as CHOLMOD implements it
// (Chen, Davis, Hager & Rajamanickam, ACM TOMS 35(3), 2008, §4): for each supernode s in turn,
//   1. L_s ← A(:, cols(s)) scattered into s's dense block (rows(s) x cols(s), column-major);
//   2. for every earlier supernode d with rows in cols(s) (the "descendants" that update s),
//        C = L_d(rows(d) ≥ first of cols(s), :) · L_d(rows(d) in cols(s), :)ᵀ   (dsyrk + dgemm)
//      and L_s −= C, scattered through the relative row map of d's rows within rows(s);
//   3. the diagonal triangle: L_ss ← chol(L_ss) (dpotrf); the rows below: L_bs ← L_bs L_ss⁻ᵀ
//      (dtrsm).
// Descendants are kept in linked lists keyed by the next supernode they update, so each d
// visits exactly the supernodes its rows reach.
//
// Why kerf has its own numeric phase rather than calling cholmod_super_numeric: CHOLMOD as
// Debian builds it opens an OpenMP parallel region per supernode (even on one thread, as an
// `if` clause), and libgomp allocates and frees a thread team for each one: a heap allocation
// inside the realtime step (the allocation counters see it; docs/reliability.md). This class allocates only in `analyse`; `factorize` calls the BLAS and
// LAPACK kernels (on one thread) and touches no allocator.

#include <cstddef>
#include <vector>

namespace kerf {

/// The symbolic structure of a supernodal factor L in CHOLMOD's layout (all arrays borrowed).
/// Supernode s holds columns super[s] … super[s+1]−1; its row indices are rows[row_start[s] …
/// row_start[s+1]−1] (ascending, the first ones its own columns); its values are a dense
/// column-major block of (row_start[s+1] − row_start[s]) rows from value_start[s].
struct SupernodalStructure {
  int n = 0;             ///< order of A
  int supernodes = 0;    ///< number of supernodes
  const int* super = nullptr;       ///< supernodes + 1 entries
  const int* row_start = nullptr;   ///< supernodes + 1 entries (CHOLMOD's L->pi)
  const int* value_start = nullptr; ///< supernodes + 1 entries (CHOLMOD's L->px)
  const int* rows = nullptr;        ///< CHOLMOD's L->s
};

/// The lower triangle of a symmetric A in compressed columns (row indices ascending in each
/// column), rows and columns already in the factor's order.
struct LowerCompressedColumns {
  const int* column_start = nullptr; ///< n + 1 entries
  const int* row = nullptr;
  const double* value = nullptr;
};

class SupernodalCholesky {
public:
  /// Sizes every workspace `factorize` needs for `structure` (allocates).
  void analyse(const SupernodalStructure& structure);

  /// L (written into `l_values`, laid out as `structure` says) with L Lᵀ = A. Entries of A
  /// outside L's pattern are an error (false). False also when A is not positive definite
  /// (the leading minor that failed is `failed_column()`). Allocation-free.
  bool factorize(const SupernodalStructure& structure, const LowerCompressedColumns& a, double* l_values) noexcept;

  /// The column at which the last `factorize` found A not positive definite, or −1.
  [[nodiscard]] int failed_column() const { return m_failed_column; }

private:
  std::vector<int> m_supernode_of; ///< per column: its supernode
  std::vector<int> m_map;          ///< per row of A: its place in the current supernode's rows
  std::vector<int> m_relative;     ///< per row of a descendant: its place in the current supernode
  std::vector<int> m_head, m_next, m_position; ///< descendant lists; next row of d to use
  std::vector<double> m_update;    ///< C of one descendant's update
  int m_failed_column = -1;
};

} // namespace kerf
