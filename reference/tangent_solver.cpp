#include "reference/tangent_solver.hpp"

#include <deal.II/lac/sparse_direct.h>

#include <petscksp.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace kerf::reference {

namespace {

void check(PetscErrorCode code, const char* what) {
  if (code != 0) throw std::runtime_error(std::string("PETSc error ") + std::to_string(code) + " in " + what);
}

void finalize_petsc() {
  PetscBool finalized = PETSC_FALSE;
  PetscFinalized(&finalized);
  if (!finalized) PetscFinalize();
}

// PETSc (and through it MPI) is initialised on first use; kerf's programs have no MPI main.
void ensure_petsc() {
  PetscBool initialized = PETSC_FALSE;
  PetscInitialized(&initialized);
  if (initialized) return;
  check(PetscInitializeNoArguments(), "PetscInitializeNoArguments");
  std::atexit(finalize_petsc);
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

TangentSolver::TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double tol)
    : m_kind(kind), m_coordinates(std::move(coordinates)), m_tolerance(tol) {}

TangentSolver::~TangentSolver() = default;

std::string TangentSolver::name() const { return m_kind == Kind::direct ? "umfpack" : "petsc-cg-gamg"; }

int TangentSolver::solve(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x,
                         const dealii::Vector<double>& b) {
  if (m_kind == Kind::direct) {
    dealii::SparseDirectUMFPACK umfpack;
    umfpack.initialize(K);
    umfpack.vmult(x, b);
    return 0;
  }
  ensure_petsc();
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
    check(KSPSetType(m_petsc->ksp, KSPCG), "KSPSetType");
    check(KSPSetNormType(m_petsc->ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    check(KSPSetTolerances(m_petsc->ksp, m_tolerance, 1e-300, PETSC_DEFAULT, 5000), "KSPSetTolerances");
    PC pc = nullptr;
    check(KSPGetPC(m_petsc->ksp, &pc), "KSPGetPC");
    check(PCSetType(pc, PCGAMG), "PCSetType");
    check(KSPSetFromOptions(m_petsc->ksp), "KSPSetFromOptions");
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
  // The six rigid-body modes from the DOF coordinates (block size 3, node-major).
  Vec coords = nullptr;
  check(VecCreateSeq(PETSC_COMM_SELF, n, &coords), "VecCreateSeq");
  check(VecSetBlockSize(coords, 3), "VecSetBlockSize");
  PetscScalar* c = nullptr;
  check(VecGetArray(coords, &c), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i) c[i] = m_coordinates[static_cast<std::size_t>(i)][static_cast<unsigned>(i % 3)];
  check(VecRestoreArray(coords, &c), "VecRestoreArray");
  MatNullSpace nullspace = nullptr;
  check(MatNullSpaceCreateRigidBody(coords, &nullspace), "MatNullSpaceCreateRigidBody");
  check(MatSetNearNullSpace(m_petsc->A, nullspace), "MatSetNearNullSpace");
  MatNullSpaceDestroy(&nullspace);
  VecDestroy(&coords);
  check(KSPSetOperators(m_petsc->ksp, m_petsc->A, m_petsc->A), "KSPSetOperators");

  PetscScalar* pb = nullptr;
  check(VecGetArray(m_petsc->b, &pb), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i) pb[i] = b[static_cast<std::size_t>(i)];
  check(VecRestoreArray(m_petsc->b, &pb), "VecRestoreArray");
  check(VecSet(m_petsc->x, 0.0), "VecSet");
  check(KSPSolve(m_petsc->ksp, m_petsc->b, m_petsc->x), "KSPSolve");
  KSPConvergedReason reason;
  check(KSPGetConvergedReason(m_petsc->ksp, &reason), "KSPGetConvergedReason");
  PetscInt iterations = 0;
  check(KSPGetIterationNumber(m_petsc->ksp, &iterations), "KSPGetIterationNumber");
  if (reason < 0)
    throw std::runtime_error("PETSc CG + GAMG did not converge (reason " + std::to_string(static_cast<int>(reason)) +
                             " after " + std::to_string(iterations) + " iterations)");
  const PetscScalar* px = nullptr;
  check(VecGetArrayRead(m_petsc->x, &px), "VecGetArrayRead");
  for (PetscInt i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = px[i];
  check(VecRestoreArrayRead(m_petsc->x, &px), "VecRestoreArrayRead");
  return static_cast<int>(iterations);
}

} // namespace kerf::reference
