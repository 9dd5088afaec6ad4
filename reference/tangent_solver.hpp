#pragma once
// TangentSolver: solves one Newton step's linear system K du = b — UMFPACK for small systems,
// PETSc CG preconditioned by GAMG with elasticity's six rigid-body modes as near null space for
// large ones (../shared/notes/dealii-on-debian12.md: without them AMG loses to Jacobi). The CG stop
// test uses the unpreconditioned (true) residual, which Newton's convergence depends on.
// Internal to reference/: includes deal.II, never included outside this folder.

#include <deal.II/base/point.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

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
  TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double relative_tolerance);
  ~TangentSolver();
  TangentSolver(const TangentSolver&) = delete;
  TangentSolver& operator=(const TangentSolver&) = delete;

  /// Solves K x = b. Returns the number of iterations (0 for the direct solver). Throws
  /// std::runtime_error if the factorisation or the iteration fails.
  int solve(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x, const dealii::Vector<double>& b);
  [[nodiscard]] Kind kind() const { return m_kind; }
  [[nodiscard]] std::string name() const;

private:
  struct Petsc;
  Kind m_kind;
  std::vector<dealii::Point<3>> m_coordinates;
  double m_tolerance;
  std::unique_ptr<Petsc> m_petsc;
};

} // namespace kerf::reference
