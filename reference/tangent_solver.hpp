#pragma once
// TangentSolver: solves one Newton step's linear system K du = b — a direct factorisation for
// small systems (sparse_direct.hpp: CHOLMOD's Cholesky when K is symmetric positive definite,
// UMFPACK's LU otherwise, the symbolic analysis done once per problem),
// PETSc CG (or GMRES) preconditioned by GAMG with elasticity's six rigid-body modes as near null
// space for large ones (../shared/notes/dealii-on-debian12.md: without them AMG loses to Jacobi).
// CG needs a symmetric positive definite tangent; contact (the penalty term ε_N p ∂n/∂x) and a
// softening cohesive interface make it indefinite, and then GMRES (right-preconditioned) is used.
// A finite-strain tangent that is SPD at equilibrium can be indefinite at a Newton iterate far from
// it (clay_pull's grasp stretched to J ≈ 1.7: CG stops with KSP_DIVERGED_INDEFINITE_MAT/_PC): CG
// then hands that system to GMRES with the same preconditioner, for that solve only (the choice
// depends on the matrix alone, so a resumed run repeats the uninterrupted one).
// The stop test uses the unpreconditioned (true) residual, which Newton's convergence depends on.
// Distributed over MPI processes (PETSc MPI matrix and vectors): MUMPS is the direct solver (a
// parallel LU), CG + GAMG the iterative one, both on the matrix's communicator.
// Internal to reference/: includes deal.II, never included outside this folder.

#include <deal.II/base/index_set.h>
#include <deal.II/base/point.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include "reference/sparse_direct.hpp"

#include <memory>
#include <string>
#include <vector>

namespace kerf::reference {

/// The iterative solver's settings beyond the tolerance (TangentSolver).
struct IterativeSettings {
  /// Give GAMG the six rigid-body modes as near null space (false: GAMG's default, the three
  /// translations of block size 3 — for the tests that show the difference).
  bool rigid_body_modes = true;
  int max_iterations = 5000; ///< Krylov iterations per solve before it counts as failed
};

/// The linear solver of one problem (the matrix pattern is fixed; values change every step).
class TangentSolver {
public:
  enum class Kind { direct, iterative };
  /// Counters of the iterative solver.
  struct IterativeCounters {
    int solves = 0;
    int iterations = 0;          ///< Krylov iterations, all solves
    int indefinite_to_gmres = 0; ///< CG solves that met an indefinite matrix or preconditioner and went to GMRES
  };
  /// `coordinates`: the support point of each DOF, in node-major order (DOFs 3k, 3k+1, 3k+2 are
  /// the x, y, z components of one node), used for the rigid-body modes of the iterative solver.
  /// `distributed`: the systems are PETSc MPI ones (the second `solve`); `coordinates` are then
  /// the support points of this process's locally owned DOFs, in their global order.
  /// `symmetric_positive_definite`: the tangents are SPD (CG); false: they may be indefinite or
  /// unsymmetric (GMRES).
  TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double relative_tolerance,
                bool distributed = false, bool symmetric_positive_definite = true,
                IterativeSettings iterative = IterativeSettings());
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
  /// Why this solver was chosen (SolverSettings::linear_solver = automatic: the DOF count, the
  /// predicted factor, a fall-back below), for the run's record; empty when none was given.
  [[nodiscard]] const std::string& choice_reason() const { return m_reason; }
  void set_choice_reason(std::string reason) { m_reason = std::move(reason); }
  /// Kind::iterative chosen automatically: when GAMG does not converge on a system (nor GMRES
  /// after an indefinite CG), solve it and every later one with the direct solver (CHOLMOD/UMFPACK,
  /// distributed MUMPS) instead of failing, and say so in choice_reason().
  void fall_back_to_direct_on_failure(bool on) { m_fall_back = on; }
  [[nodiscard]] const IterativeCounters& iterative_counters() const { return m_iterative_counters; }
  /// Where the solves' time went, summed since construction [s]: `setup`, the factorisations
  /// (serial direct: CHOLMOD's/UMFPACK's analyses and numeric factorisations; MUMPS: PETSc's
  /// PCSetUp) or the preconditioner's set-up (GAMG); `solve`, the forward and back substitutions or
  /// the Krylov iterations. Distributed, this process's wall time, the communication inside MUMPS,
  /// GAMG and the Krylov method included.
  struct Timings {
    double setup_seconds = 0.0;
    double solve_seconds = 0.0;
  };
  [[nodiscard]] Timings timings() const;
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
  Timings m_petsc_timings; ///< the PETSc solves' (the serial direct solver's are its counters)
  bool m_distributed;
  bool m_spd;
  IterativeSettings m_iterative;
  IterativeCounters m_iterative_counters;
  std::string m_reason;
  bool m_fall_back = false;
  void switch_to_direct(const std::string& why);
  int solve_iterative(const dealii::PETScWrappers::MPI::SparseMatrix& K, dealii::PETScWrappers::MPI::Vector& x,
                      const dealii::PETScWrappers::MPI::Vector& b);
  int solve_iterative(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x, const dealii::Vector<double>& b);
  int run_iterative(Vec b, Vec x); ///< PETSc Vecs: CG (or GMRES), GMRES again if CG meets indefiniteness
  void make_direct(const dealii::SparsityPattern& pattern);
};

/// The entries of the Cholesky factor that CHOLMOD's analysis predicts for the global matrix of a
/// distributed pattern (collective over `comm`): each process's locally owned rows of `pattern`
/// (`owned`, one contiguous range) are gathered to rank 0 and analysed there as the serial solver
/// analyses its pattern (SparseDirect::predict_cholesky_factor_entries), and the number is
/// broadcast. When the lower triangle alone holds more than `limit` entries (so the factor does
/// too) nothing is gathered and +infinity is returned.
double distributed_cholesky_factor_entries(const dealii::DynamicSparsityPattern& pattern, const dealii::IndexSet& owned,
                                           MPI_Comm comm, double limit);

} // namespace kerf::reference
