#pragma once
// TangentSolver: solves one Newton step's linear system K du = b — a direct factorisation for
// small systems (sparse_direct.hpp: CHOLMOD's Cholesky when K is symmetric positive definite,
// UMFPACK's LU otherwise, the symbolic analysis done once per problem),
// PETSc CG (or GMRES) preconditioned by GAMG with elasticity's six rigid-body modes as near null
// space for large ones (../shared/notes/dealii-on-debian12.md: without them AMG loses to Jacobi).
// CG needs a symmetric positive definite tangent; contact (the penalty term ε_N p ∂n/∂x) and a
// softening cohesive interface make it indefinite, and then GMRES (right-preconditioned) is used.
// The stop test uses the unpreconditioned (true) residual, which Newton's convergence depends on.
// Distributed over MPI processes (PETSc MPI matrix and vectors): MUMPS is the direct solver (a
// parallel LU), CG + GAMG the iterative one, both on the matrix's communicator.
// Internal to reference/: includes deal.II, never included outside this folder.

#include <deal.II/base/point.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include "reference/sparse_direct.hpp"

#include <memory>
#include <string>
#include <vector>

namespace kerf::reference {

/// The linear solver of one problem (the matrix pattern is fixed; values change every step).
class TangentSolver {
public:
  enum class Kind { direct, iterative };
  /// `coordinates`: the support point of each DOF, in node-major order (DOFs 3k, 3k+1, 3k+2 are
  /// the x, y, z components of one node), used for the rigid-body modes of the iterative solver.
  /// `distributed`: the systems are PETSc MPI ones (the second `solve`); `coordinates` are then
  /// the support points of this process's locally owned DOFs, in their global order.
  /// `symmetric_positive_definite`: the tangents are SPD (CG); false: they may be indefinite or
  /// unsymmetric (GMRES).
  TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double relative_tolerance,
                bool distributed = false, bool symmetric_positive_definite = true);
  ~TangentSolver();
  TangentSolver(const TangentSolver&) = delete;
  TangentSolver& operator=(const TangentSolver&) = delete;

  /// Solves K x = b. Returns the number of iterations (0 for the direct solver). Throws
  /// std::runtime_error if the factorisation or the iteration fails.
  int solve(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x, const dealii::Vector<double>& b);
  /// Serial direct solver only: the entries of the Cholesky factor of a matrix with this pattern,
  /// as CHOLMOD's analysis predicts them (SparseDirect::cholesky_factor_entries; the analysis is
  /// kept for the factorisations of matrices of this pattern).
  double cholesky_factor_entries(const dealii::SparsityPattern& pattern);
  /// Serial direct solver only: factorises K (kept for `solve_factorized`).
  void factorize(const dealii::SparseMatrix<double>& K);
  /// Serial direct solver: whether a factorisation is at hand (the last `factorize` succeeded).
  [[nodiscard]] bool factorized() const { return m_factorized; }
  /// Serial direct solver only: solves K x = b with the last factorisation.
  void solve_factorized(dealii::Vector<double>& x, const dealii::Vector<double>& b) const;
  /// Serial direct solver: its counters (factorisations, times); nullptr before the first solve.
  [[nodiscard]] const SparseDirect::Counters* direct_counters() const {
    return m_direct ? &m_direct->counters() : nullptr;
  }
  /// Solves K x = b distributed over K's communicator (collective): MUMPS for Kind::direct, CG +
  /// GAMG for Kind::iterative. Same return value and errors as the serial overload.
  int solve(const dealii::PETScWrappers::MPI::SparseMatrix& K, dealii::PETScWrappers::MPI::Vector& x,
            const dealii::PETScWrappers::MPI::Vector& b);
  [[nodiscard]] Kind kind() const { return m_kind; }
  /// "cholmod/umfpack" / "mumps" (direct, serial / distributed), "petsc-cg-gamg" or "petsc-gmres-gamg".
  [[nodiscard]] std::string name() const;

private:
  struct Petsc;
  Kind m_kind;
  std::vector<dealii::Point<3>> m_coordinates;
  double m_tolerance;
  std::unique_ptr<Petsc> m_petsc;
  std::unique_ptr<SparseDirect> m_direct; ///< serial direct: built from K's pattern on first use
  std::vector<double> m_values;           ///< K's values in its pattern's order
  bool m_factorized = false;
  bool m_distributed;
  bool m_spd;
  void make_direct(const dealii::SparsityPattern& pattern);
};

} // namespace kerf::reference
