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

#include <cstddef>

namespace kerf::reference {

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
  [[nodiscard]] bool owns(dealii::types::global_dof_index) const { return true; }
  void prepare(dealii::AffineConstraints<double>&) const {}
};

/// The linear algebra of the distributed mesh: PETSc MPI vectors and matrix over the locally
/// owned DOFs of this process, ghosted copies for the locally relevant ones.
struct DistributedAlgebra {
  using VectorType = dealii::PETScWrappers::MPI::Vector;
  using MatrixType = dealii::PETScWrappers::MPI::SparseMatrix;
  MPI_Comm comm = MPI_COMM_WORLD;
  dealii::IndexSet owned, relevant;
  MatrixType K;
  VectorType u;
  VectorType u_previous; ///< the converged state before the last one (the predictor's u₀)
  VectorType free_mask;
  mutable VectorType ghost; ///< locally relevant values of the last vector passed to ghosted()
  void reinit(VectorType& v) const { v.reinit(owned, comm); }
  /// `v` (locally owned values) with the ghost values of the locally relevant DOFs (collective).
  const VectorType& ghosted(const VectorType& v) const {
    ghost = v;
    return ghost;
  }
  [[nodiscard]] bool owns(dealii::types::global_dof_index i) const { return owned.is_element(i); }
  void prepare(dealii::AffineConstraints<double>& c) const { c.reinit(relevant); }
};

} // namespace kerf::reference
