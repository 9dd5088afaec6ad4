#pragma once
// The two linear algebras of the finite-strain solver (finite_strain_impl.hpp): one Newton, line
// search and assembly are written once for both, as templates on the algebra.
//
// SerialAlgebra: deal.II's Vector and SparseMatrix on this process alone (UMFPACK/CHOLMOD or PETSc
// CG). DistributedAlgebra: the mesh distributed over the MPI processes as a
// parallel::fullydistributed::Triangulation, PETSc MPI vectors and matrix over each process's
// locally owned DOFs (MUMPS or CG + GAMG on MPI_COMM_WORLD). Each process assembles its locally
// owned cells; norms, contact resultants and reactions are summed over the processes.

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <chrono>
#include <cstddef>
#include <vector>

namespace kerf::reference {

/// Adds the wall time of its scope to `total` [s] (the solver's timings, SolverTimings).
class ScopedTimer {
public:
  explicit ScopedTimer(double& total) : m_total(total), m_begin(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() { m_total += std::chrono::duration<double>(std::chrono::steady_clock::now() - m_begin).count(); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

private:
  double& m_total;
  std::chrono::steady_clock::time_point m_begin;
};

/// The linear algebra of one process alone: deal.II's serial vector and sparse matrix.
struct SerialAlgebra {
  using VectorType = dealii::Vector<double>;
  using MatrixType = dealii::SparseMatrix<double>;
  std::size_t n = 0;
  dealii::SparsityPattern pattern;
  MatrixType K;
  VectorType u;          ///< the displacement DOFs
  VectorType u_previous; ///< the converged state before the last one (the predictor's u₀)
  VectorType free_mask;  ///< 1 on free DOFs, 0 on Dirichlet DOFs
  void reinit(VectorType& v) const { v.reinit(n); }
  /// The vector with the values every cell of this process reads: itself.
  const VectorType& ghosted(const VectorType& v) const { return v; }
  /// The same, as the assembly reads it (entry by entry at global DOF indices): itself.
  const dealii::Vector<double>& readable(const VectorType& v) const { return v; }
  [[nodiscard]] bool owns(dealii::types::global_dof_index) const { return true; }
  void prepare(dealii::AffineConstraints<double>&) const {}
};

/// The linear algebra of the distributed mesh: PETSc MPI vectors and matrix over the locally
/// owned DOFs of this process, ghosted copies for the locally relevant ones.
struct DistributedAlgebra {
  using VectorType = dealii::PETScWrappers::MPI::Vector;
  using MatrixType = dealii::PETScWrappers::MPI::SparseMatrix;
  MPI_Comm comm = MPI_COMM_WORLD;
  /// The locally owned DOFs, and the locally relevant ones: those of the owned and ghost cells,
  /// and the DOFs of this process's cohesive face pairs, whose − cell may be another process's.
  dealii::IndexSet owned, relevant;
  MatrixType K;
  VectorType u;
  VectorType u_previous; ///< the converged state before the last one (the predictor's u₀)
  VectorType free_mask;
  mutable VectorType ghost; ///< locally relevant values of the last vector passed to ghosted()
  mutable double exchange_seconds = 0.0; ///< wall time in ghosted() (SolverTimings::communication_seconds)
  void reinit(VectorType& v) const { v.reinit(owned, comm); }
  /// `v` (locally owned values) with the ghost values of the locally relevant DOFs (collective).
  const VectorType& ghosted(const VectorType& v) const {
    const ScopedTimer timer(exchange_seconds);
    ghost = v;
    return ghost;
  }
  /// `v`'s locally relevant values (ghosted(), collective) in a plain vector at their global DOF
  /// indices, the other entries unset: what the assembly reads entry by entry, each at the cost
  /// of an array access (an entry of a ghosted PETSc vector costs a VecGetArray/VecRestoreArray
  /// pair and, for a ghost, a search of the ghost index set).
  const dealii::Vector<double>& readable(const VectorType& v) const {
    const VectorType& g = ghosted(v);
    if (relevant_indices.size() != relevant.n_elements()) {
      relevant_indices.assign(relevant.begin(), relevant.end());
      relevant_values.resize(relevant_indices.size());
      local.reinit(owned.size());
    }
    g.extract_subvector_to(relevant_indices.begin(), relevant_indices.end(), relevant_values.begin());
    for (std::size_t k = 0; k < relevant_indices.size(); ++k) local[relevant_indices[k]] = relevant_values[k];
    return local;
  }
  [[nodiscard]] bool owns(dealii::types::global_dof_index i) const { return owned.is_element(i); }
  void prepare(dealii::AffineConstraints<double>& c) const { c.reinit(relevant); }

private:
  mutable std::vector<dealii::types::global_dof_index> relevant_indices;
  mutable std::vector<double> relevant_values;
  mutable dealii::Vector<double> local; ///< readable()'s values (all DOFs; the relevant ones set)
};

} // namespace kerf::reference
