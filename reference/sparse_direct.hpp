#pragma once
// SparseDirect: the direct solver of the reference's Newton systems K du = b, on one process.
// The sparsity pattern of K is fixed for a problem (the DOF couplings of the mesh, the cohesive
// pairs), so its analysis — the fill-reducing ordering and the symbolic factorisation — is done
// once and reused by every numeric factorisation, for every Newton iteration of every sample.
//
// Per factorisation it picks the cheapest exact method the values allow:
//   - K symmetric (|K_ij − K_ji| <= 1e-12 max|K| for every entry): supernodal Cholesky K = L Lᵀ
//     (CHOLMOD, Davis & Hager; BLAS-3 on the supernodes). Elasticity's tangent is symmetric (it is
//     the Hessian of the potential energy, with the penalty contact and the cohesive law's
//     potential added) and positive definite at stable equilibria.
//   - otherwise, or when Cholesky meets a non-positive pivot (a softening interface, a buckling
//     mode): LU with partial pivoting (UMFPACK), whose symbolic analysis is also kept.
// Both solve to machine precision: the answer differs from any other direct solver's by rounding.
// The choice depends on the matrix alone (no state carried between factorisations), so that the
// same matrix always gets the same factors.
//
// Plain C++ (SuiteSparse's C interface inside the .cpp): no deal.II in this header.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kerf::reference {

class SparseDirect {
public:
  /// The pattern of an n × n matrix in compressed rows: row r's columns are
  /// columns[row_start[r] .. row_start[r+1]), in any order, without duplicates. Values are passed
  /// to `factorize` in the same order.
  SparseDirect(std::size_t n, std::vector<std::int64_t> row_start, std::vector<std::int64_t> columns);
  ~SparseDirect();
  SparseDirect(const SparseDirect&) = delete;
  SparseDirect& operator=(const SparseDirect&) = delete;

  /// Factorises K (its values in the pattern's order): Cholesky when symmetric positive definite,
  /// LU otherwise (see file comment). Throws std::runtime_error when K is singular.
  void factorize(const std::vector<double>& values);
  /// Solves K x = b with the last factorisation (x and b of size n; may not alias).
  void solve(const double* b, double* x) const;
  /// The entries of the Cholesky factor L that CHOLMOD's analysis of the pattern predicts (its
  /// fill-reducing ordering; the analysis is kept for the factorisations): the memory a direct
  /// solve needs, 8 bytes an entry for L (UMFPACK's LU, when it takes over, several times that).
  [[nodiscard]] double cholesky_factor_entries();
  /// The same prediction for a pattern given in compressed rows (as the constructor takes it),
  /// without building a solver: CHOLMOD's analysis of the same lower triangle, so a pattern gives
  /// the same number either way (the distributed solver's automatic choice gathers its pattern
  /// and asks this, tangent_solver.hpp).
  [[nodiscard]] static double predict_cholesky_factor_entries(std::size_t n, const std::vector<std::int64_t>& row_start,
                                                              const std::vector<std::int64_t>& columns);

  /// Work counters since construction.
  struct Counters {
    int cholesky = 0;          ///< Cholesky factorisations that succeeded
    int lu = 0;                ///< LU factorisations
    int not_positive_definite = 0; ///< symmetric matrices on which Cholesky failed (then LU)
    int solves = 0;
    double analysis_seconds = 0.0;      ///< orderings and symbolic factorisations
    double factorization_seconds = 0.0; ///< numeric factorisations
    double solve_seconds = 0.0;         ///< forward and back substitutions
  };
  [[nodiscard]] const Counters& counters() const { return m_counters; }
  /// "cholmod" or "umfpack": the method of the last factorisation.
  [[nodiscard]] std::string last_method() const;

private:
  struct Cholmod;
  struct Umfpack;
  std::size_t m_n;
  std::vector<std::int64_t> m_row_start, m_columns;
  std::vector<std::int64_t> m_transpose; ///< entry e = (i, j) -> the entry (j, i), or -1
  std::unique_ptr<Cholmod> m_cholmod;
  std::unique_ptr<Umfpack> m_umfpack;
  bool m_last_cholesky = false;
  mutable Counters m_counters;
  [[nodiscard]] bool symmetric(const std::vector<double>& values) const;
  void analyze_cholesky();
  bool factorize_cholesky(const std::vector<double>& values);
  void factorize_lu(const std::vector<double>& values);
};

} // namespace kerf::reference
