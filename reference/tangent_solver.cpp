#include "reference/tangent_solver.hpp"

#include "reference/mpi_processes.hpp"


#include <petscksp.h>

#include <stdexcept>
#include <string>

namespace kerf::reference {

namespace {

void check(PetscErrorCode code, const char* what) {
  if (code != 0) throw std::runtime_error(std::string("PETSc error ") + std::to_string(code) + " in " + what);
}

/// CG on the true residual, preconditioned by GAMG (the near null space is set on the matrix).
/// CG (SPD tangents) or GMRES (indefinite ones: right-preconditioned, so that its residual is the
/// true one; restart 200) with GAMG, stopping at a true residual of `tolerance` |b|.
void configure_krylov_gamg(KSP ksp, double tolerance, bool spd) {
  if (spd) {
    check(KSPSetType(ksp, KSPCG), "KSPSetType");
  } else {
    check(KSPSetType(ksp, KSPGMRES), "KSPSetType");
    check(KSPGMRESSetRestart(ksp, 200), "KSPGMRESSetRestart");
    check(KSPSetPCSide(ksp, PC_RIGHT), "KSPSetPCSide");
  }
  check(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  check(KSPSetTolerances(ksp, tolerance, 1e-300, PETSC_DEFAULT, 5000), "KSPSetTolerances");
  PC pc = nullptr;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  check(PCSetType(pc, PCGAMG), "PCSetType");
  check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
}

/// Gives `A` elasticity's six rigid-body modes as near null space, built from the support points
/// of its locally owned rows (block size 3, node-major).
void set_rigid_body_modes(Mat A, MPI_Comm comm, const std::vector<dealii::Point<3>>& coordinates) {
  const auto n = static_cast<PetscInt>(coordinates.size());
  Vec coords = nullptr;
  check(VecCreateMPI(comm, n, PETSC_DETERMINE, &coords), "VecCreateMPI");
  check(VecSetBlockSize(coords, 3), "VecSetBlockSize");
  PetscScalar* c = nullptr;
  check(VecGetArray(coords, &c), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i) c[i] = coordinates[static_cast<std::size_t>(i)][static_cast<unsigned>(i % 3)];
  check(VecRestoreArray(coords, &c), "VecRestoreArray");
  MatNullSpace nullspace = nullptr;
  check(MatNullSpaceCreateRigidBody(coords, &nullspace), "MatNullSpaceCreateRigidBody");
  check(MatSetNearNullSpace(A, nullspace), "MatSetNearNullSpace");
  MatNullSpaceDestroy(&nullspace);
  VecDestroy(&coords);
}

/// Runs the KSP; throws naming the solver if it did not converge. Returns the iteration count.
int run_ksp(KSP ksp, Vec b, Vec x, const std::string& name) {
  check(KSPSolve(ksp, b, x), "KSPSolve");
  KSPConvergedReason reason;
  check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
  PetscInt iterations = 0;
  check(KSPGetIterationNumber(ksp, &iterations), "KSPGetIterationNumber");
  if (reason < 0)
    throw std::runtime_error(name + " did not converge (reason " + std::to_string(static_cast<int>(reason)) +
                             " after " + std::to_string(iterations) + " iterations)");
  return static_cast<int>(iterations);
}

} // namespace

struct TangentSolver::Petsc {
  Mat A = nullptr;
  Vec x = nullptr, b = nullptr;
  KSP ksp = nullptr;
  ~Petsc() {
    if (ksp) KSPDestroy(&ksp);
    if (x) VecDestroy(&x);
    if (b) VecDestroy(&b);
    if (A) MatDestroy(&A);
  }
};

TangentSolver::TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double tol, bool distributed,
                             bool spd)
    : m_kind(kind), m_coordinates(std::move(coordinates)), m_tolerance(tol), m_distributed(distributed), m_spd(spd) {}

TangentSolver::~TangentSolver() = default;

std::string TangentSolver::name() const {
  if (m_kind == Kind::iterative) return m_spd ? "petsc-cg-gamg" : "petsc-gmres-gamg";
  return m_distributed ? "mumps" : "cholmod/umfpack";
}

void TangentSolver::make_direct(const dealii::SparsityPattern& pattern) {
  if (m_direct) return;
  // The pattern in deal.II's storage order (each row's diagonal first), once per problem.
  std::vector<std::int64_t> row_start{0}, columns;
  columns.reserve(pattern.n_nonzero_elements());
  for (std::size_t r = 0; r < pattern.n_rows(); ++r) {
    for (auto it = pattern.begin(r); it != pattern.end(r); ++it) columns.push_back(static_cast<std::int64_t>(it->column()));
    row_start.push_back(static_cast<std::int64_t>(columns.size()));
  }
  m_values.resize(columns.size());
  m_direct = std::make_unique<SparseDirect>(pattern.n_rows(), std::move(row_start), std::move(columns));
}

double TangentSolver::cholesky_factor_entries(const dealii::SparsityPattern& pattern) {
  if (m_kind != Kind::direct || m_distributed)
    throw std::logic_error("TangentSolver::cholesky_factor_entries: serial direct solver only");
  make_direct(pattern);
  return m_direct->cholesky_factor_entries();
}

void TangentSolver::factorize(const dealii::SparseMatrix<double>& K) {
  if (m_kind != Kind::direct || m_distributed) throw std::logic_error("TangentSolver::factorize: serial direct solver only");
  make_direct(K.get_sparsity_pattern());
  std::size_t k = 0;
  for (std::size_t r = 0; r < K.m(); ++r)
    for (auto it = K.begin(r); it != K.end(r); ++it) m_values[k++] = it->value();
  m_factorized = false;
  m_direct->factorize(m_values);
  m_factorized = true;
}

void TangentSolver::solve_factorized(dealii::Vector<double>& x, const dealii::Vector<double>& b) const {
  if (!m_direct) throw std::logic_error("TangentSolver::solve_factorized: no factorisation");
  m_direct->solve(b.begin(), x.begin());
}

int TangentSolver::solve(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x,
                         const dealii::Vector<double>& b) {
  if (m_kind == Kind::direct) {
    factorize(K);
    solve_factorized(x, b);
    return 0;
  }
  initialize_petsc();
  const auto n = static_cast<PetscInt>(K.m());
  if (!m_petsc) {
    m_petsc = std::make_unique<Petsc>();
    const auto& pattern = K.get_sparsity_pattern();
    std::vector<PetscInt> nnz(K.m());
    for (std::size_t r = 0; r < K.m(); ++r) nnz[r] = static_cast<PetscInt>(pattern.row_length(r));
    check(MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 0, nnz.data(), &m_petsc->A), "MatCreateSeqAIJ");
    check(MatSetBlockSize(m_petsc->A, 3), "MatSetBlockSize");
    check(MatSetOption(m_petsc->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
    check(MatCreateVecs(m_petsc->A, &m_petsc->x, &m_petsc->b), "MatCreateVecs");
    check(KSPCreate(PETSC_COMM_SELF, &m_petsc->ksp), "KSPCreate");
    configure_krylov_gamg(m_petsc->ksp, m_tolerance, m_spd);
  }
  // Copy the values row by row (PETSc sorts the columns).
  check(MatZeroEntries(m_petsc->A), "MatZeroEntries");
  std::vector<PetscInt> cols;
  std::vector<PetscScalar> vals;
  for (std::size_t r = 0; r < K.m(); ++r) {
    cols.clear();
    vals.clear();
    for (auto it = K.begin(r); it != K.end(r); ++it) {
      cols.push_back(static_cast<PetscInt>(it->column()));
      vals.push_back(it->value());
    }
    const auto row = static_cast<PetscInt>(r);
    check(MatSetValues(m_petsc->A, 1, &row, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(), INSERT_VALUES),
          "MatSetValues");
  }
  check(MatAssemblyBegin(m_petsc->A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(m_petsc->A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  set_rigid_body_modes(m_petsc->A, PETSC_COMM_SELF, m_coordinates);
  check(KSPSetOperators(m_petsc->ksp, m_petsc->A, m_petsc->A), "KSPSetOperators");

  PetscScalar* pb = nullptr;
  check(VecGetArray(m_petsc->b, &pb), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i) pb[i] = b[static_cast<std::size_t>(i)];
  check(VecRestoreArray(m_petsc->b, &pb), "VecRestoreArray");
  check(VecSet(m_petsc->x, 0.0), "VecSet");
  const int iterations = run_ksp(m_petsc->ksp, m_petsc->b, m_petsc->x, m_spd ? "PETSc CG + GAMG" : "PETSc GMRES + GAMG");
  const PetscScalar* px = nullptr;
  check(VecGetArrayRead(m_petsc->x, &px), "VecGetArrayRead");
  for (PetscInt i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = px[i];
  check(VecRestoreArrayRead(m_petsc->x, &px), "VecRestoreArrayRead");
  return iterations;
}

int TangentSolver::solve(const dealii::PETScWrappers::MPI::SparseMatrix& K, dealii::PETScWrappers::MPI::Vector& x,
                         const dealii::PETScWrappers::MPI::Vector& b) {
  const MPI_Comm comm = K.get_mpi_communicator();
  Mat A = static_cast<Mat>(K);
  if (!m_petsc) {
    m_petsc = std::make_unique<Petsc>();
    check(KSPCreate(comm, &m_petsc->ksp), "KSPCreate");
    if (m_kind == Kind::direct) {
      // MUMPS: a parallel sparse LU (the tangent with contact need not be symmetric).
      check(KSPSetType(m_petsc->ksp, KSPPREONLY), "KSPSetType");
      PC pc = nullptr;
      check(KSPGetPC(m_petsc->ksp, &pc), "KSPGetPC");
      check(PCSetType(pc, PCLU), "PCSetType");
      check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
      check(KSPSetFromOptions(m_petsc->ksp), "KSPSetFromOptions");
    } else {
      // GAMG needs block size 3 for the rigid-body modes, which deal.II's matrix was created
      // without: a copy with block size 3 and the same rows (preallocated once, values every step).
      PetscInt first = 0, last = 0;
      check(MatGetOwnershipRange(A, &first, &last), "MatGetOwnershipRange");
      std::vector<PetscInt> diagonal(static_cast<std::size_t>(last - first)), off(diagonal.size());
      for (PetscInt r = first; r < last; ++r) {
        PetscInt ncols = 0;
        const PetscInt* cols = nullptr;
        check(MatGetRow(A, r, &ncols, &cols, nullptr), "MatGetRow");
        for (PetscInt k = 0; k < ncols; ++k)
          ++(cols[k] >= first && cols[k] < last ? diagonal : off)[static_cast<std::size_t>(r - first)];
        check(MatRestoreRow(A, r, &ncols, &cols, nullptr), "MatRestoreRow");
      }
      check(MatCreate(comm, &m_petsc->A), "MatCreate");
      check(MatSetSizes(m_petsc->A, last - first, last - first, PETSC_DETERMINE, PETSC_DETERMINE), "MatSetSizes");
      check(MatSetBlockSize(m_petsc->A, 3), "MatSetBlockSize");
      check(MatSetType(m_petsc->A, MATAIJ), "MatSetType");
      check(MatMPIAIJSetPreallocation(m_petsc->A, 0, diagonal.data(), 0, off.data()), "MatMPIAIJSetPreallocation");
      check(MatSeqAIJSetPreallocation(m_petsc->A, 0, diagonal.data()), "MatSeqAIJSetPreallocation");
      check(MatSetOption(m_petsc->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
      configure_krylov_gamg(m_petsc->ksp, m_tolerance, m_spd);
    }
  }
  if (m_kind == Kind::iterative) {
    PetscInt first = 0, last = 0;
    check(MatGetOwnershipRange(A, &first, &last), "MatGetOwnershipRange");
    check(MatZeroEntries(m_petsc->A), "MatZeroEntries");
    for (PetscInt r = first; r < last; ++r) {
      PetscInt ncols = 0;
      const PetscInt* cols = nullptr;
      const PetscScalar* vals = nullptr;
      check(MatGetRow(A, r, &ncols, &cols, &vals), "MatGetRow");
      check(MatSetValues(m_petsc->A, 1, &r, ncols, cols, vals, INSERT_VALUES), "MatSetValues");
      check(MatRestoreRow(A, r, &ncols, &cols, &vals), "MatRestoreRow");
    }
    check(MatAssemblyBegin(m_petsc->A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    check(MatAssemblyEnd(m_petsc->A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    set_rigid_body_modes(m_petsc->A, comm, m_coordinates);
    A = m_petsc->A;
  }
  check(KSPSetOperators(m_petsc->ksp, A, A), "KSPSetOperators");
  Vec xv = static_cast<const Vec&>(x);
  check(VecSet(xv, 0.0), "VecSet");
  if (m_kind == Kind::direct) {
    run_ksp(m_petsc->ksp, static_cast<const Vec&>(b), xv, "MUMPS");
    return 0;
  }
  return run_ksp(m_petsc->ksp, static_cast<const Vec&>(b), xv, m_spd ? "PETSc CG + GAMG" : "PETSc GMRES + GAMG");
}

} // namespace kerf::reference
