#include "reference/tangent_solver.hpp"

#include "reference/mpi_processes.hpp"


#include <petscksp.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace kerf::reference {

namespace {

void check(PetscErrorCode code, const char* what) {
  if (code != 0) throw std::runtime_error(std::string("PETSc error ") + std::to_string(code) + " in " + what);
}

/// CG (SPD tangents) or GMRES (indefinite ones: right-preconditioned, so that its residual is the
/// true one; restart 200), preconditioned by GAMG (the near null space is set on the matrix),
/// stopping at a true residual of `tolerance` |b| or failing after `max_iterations`.
void configure_krylov(KSP ksp, double tolerance, bool spd, int max_iterations) {
  if (spd) {
    check(KSPSetType(ksp, KSPCG), "KSPSetType");
  } else {
    check(KSPSetType(ksp, KSPGMRES), "KSPSetType");
    check(KSPGMRESSetRestart(ksp, 200), "KSPGMRESSetRestart");
    check(KSPSetPCSide(ksp, PC_RIGHT), "KSPSetPCSide");
  }
  check(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  check(KSPSetTolerances(ksp, tolerance, 1e-300, PETSC_DEFAULT, max_iterations), "KSPSetTolerances");
}

/// The Krylov solver with a fresh GAMG preconditioner; PETSc's options (PETSC_OPTIONS) may override.
void configure_krylov_gamg(KSP ksp, double tolerance, bool spd, int max_iterations) {
  configure_krylov(ksp, tolerance, spd, max_iterations);
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

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Runs the KSP: its reason and iteration count. The set-up (MUMPS's factorisation, GAMG's
/// hierarchy; KSPSolve would run it first anyway) and the solve are timed apart into `timings`.
std::pair<KSPConvergedReason, int> run_ksp(KSP ksp, Vec b, Vec x, TangentSolver::Timings& timings) {
  check(VecSet(x, 0.0), "VecSet");
  auto t0 = std::chrono::steady_clock::now();
  check(KSPSetUp(ksp), "KSPSetUp");
  timings.setup_seconds += seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  check(KSPSolve(ksp, b, x), "KSPSolve");
  timings.solve_seconds += seconds_since(t0);
  KSPConvergedReason reason;
  check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
  PetscInt iterations = 0;
  check(KSPGetIterationNumber(ksp, &iterations), "KSPGetIterationNumber");
  return {reason, static_cast<int>(iterations)};
}

[[noreturn]] void throw_not_converged(const std::string& name, KSPConvergedReason reason, int iterations) {
  throw std::runtime_error(name + " did not converge (reason " + std::to_string(static_cast<int>(reason)) + " after " +
                           std::to_string(iterations) + " iterations)");
}

} // namespace

struct TangentSolver::Petsc {
  Mat A = nullptr;
  Vec x = nullptr, b = nullptr;
  KSP ksp = nullptr;
  KSP gmres = nullptr; ///< CG's fallback on an indefinite system: GMRES sharing ksp's preconditioner
  KSP mumps = nullptr; ///< distributed direct solver (Kind::direct, or the iterative one's fall-back)
  ~Petsc() {
    if (mumps) KSPDestroy(&mumps);
    if (gmres) KSPDestroy(&gmres);
    if (ksp) KSPDestroy(&ksp);
    if (x) VecDestroy(&x);
    if (b) VecDestroy(&b);
    if (A) MatDestroy(&A);
  }
};

TangentSolver::TangentSolver(Kind kind, std::vector<dealii::Point<3>> coordinates, double tol, bool distributed,
                             bool spd, IterativeSettings iterative)
    : m_kind(kind), m_coordinates(std::move(coordinates)), m_tolerance(tol), m_distributed(distributed), m_spd(spd),
      m_iterative(iterative) {}

int TangentSolver::run_iterative(Vec b, Vec x) {
  const std::string name = m_spd ? "PETSc CG + GAMG" : "PETSc GMRES + GAMG";
  auto [reason, iterations] = run_ksp(m_petsc->ksp, b, x, m_petsc_timings);
  ++m_iterative_counters.solves;
  m_iterative_counters.iterations += iterations;
  if (m_spd && (reason == KSP_DIVERGED_INDEFINITE_MAT || reason == KSP_DIVERGED_INDEFINITE_PC)) {
    // CG met p·Kp <= 0 or r·Mr <= 0: this tangent (or GAMG built on it) is indefinite. GMRES
    // with the same preconditioner (already set up for this matrix) solves it.
    if (!m_petsc->gmres) {
      MPI_Comm comm = MPI_COMM_NULL;
      check(PetscObjectGetComm(reinterpret_cast<PetscObject>(m_petsc->ksp), &comm), "PetscObjectGetComm");
      check(KSPCreate(comm, &m_petsc->gmres), "KSPCreate");
      // At most 1000 iterations: where GMRES + GAMG converges on these tangents it does so in a
      // few hundred (five restarts); a system it cannot solve should fail in seconds, not minutes.
      configure_krylov(m_petsc->gmres, m_tolerance, false, std::min(m_iterative.max_iterations, 1000));
      PC pc = nullptr;
      check(KSPGetPC(m_petsc->ksp, &pc), "KSPGetPC");
      check(KSPSetPC(m_petsc->gmres, pc), "KSPSetPC");
    }
    Mat A = nullptr, P = nullptr;
    check(KSPGetOperators(m_petsc->ksp, &A, &P), "KSPGetOperators");
    check(KSPSetOperators(m_petsc->gmres, A, P), "KSPSetOperators");
    const int cg_iterations = iterations;
    std::tie(reason, iterations) = run_ksp(m_petsc->gmres, b, x, m_petsc_timings);
    ++m_iterative_counters.indefinite_to_gmres;
    m_iterative_counters.iterations += iterations;
    if (reason < 0)
      throw std::runtime_error(name + " met an indefinite system after " + std::to_string(cg_iterations) +
                               " iterations and GMRES did not converge either (reason " +
                               std::to_string(static_cast<int>(reason)) + " after " + std::to_string(iterations) +
                               " iterations)");
    return cg_iterations + iterations;
  }
  if (reason < 0) throw_not_converged(name, reason, iterations);
  return iterations;
}

TangentSolver::~TangentSolver() = default;

std::string TangentSolver::name() const {
  if (m_kind == Kind::iterative) return m_spd ? "petsc-cg-gamg" : "petsc-gmres-gamg";
  return m_distributed ? "mumps" : "cholmod/umfpack";
}

TangentSolver::Timings TangentSolver::timings() const {
  Timings t = m_petsc_timings;
  if (m_direct) {
    t.setup_seconds += m_direct->counters().analysis_seconds + m_direct->counters().factorization_seconds;
    t.solve_seconds += m_direct->counters().solve_seconds;
  }
  return t;
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

void TangentSolver::switch_to_direct(const std::string& why) {
  m_kind = Kind::direct;
  m_reason += (m_reason.empty() ? "" : "; ") + std::string("then direct: ") + why;
}

int TangentSolver::solve(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x,
                         const dealii::Vector<double>& b) {
  if (m_kind == Kind::iterative) {
    try {
      return solve_iterative(K, x, b);
    } catch (const std::runtime_error& e) {
      if (!m_fall_back) throw;
      switch_to_direct(e.what());
    }
  }
  factorize(K);
  solve_factorized(x, b);
  return 0;
}

int TangentSolver::solve_iterative(const dealii::SparseMatrix<double>& K, dealii::Vector<double>& x,
                                   const dealii::Vector<double>& b) {
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
    configure_krylov_gamg(m_petsc->ksp, m_tolerance, m_spd, m_iterative.max_iterations);
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
  if (m_iterative.rigid_body_modes) set_rigid_body_modes(m_petsc->A, PETSC_COMM_SELF, m_coordinates);
  check(KSPSetOperators(m_petsc->ksp, m_petsc->A, m_petsc->A), "KSPSetOperators");

  PetscScalar* pb = nullptr;
  check(VecGetArray(m_petsc->b, &pb), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i) pb[i] = b[static_cast<std::size_t>(i)];
  check(VecRestoreArray(m_petsc->b, &pb), "VecRestoreArray");
  const int iterations = run_iterative(m_petsc->b, m_petsc->x);
  const PetscScalar* px = nullptr;
  check(VecGetArrayRead(m_petsc->x, &px), "VecGetArrayRead");
  for (PetscInt i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = px[i];
  check(VecRestoreArrayRead(m_petsc->x, &px), "VecRestoreArrayRead");
  return iterations;
}

int TangentSolver::solve(const dealii::PETScWrappers::MPI::SparseMatrix& K, dealii::PETScWrappers::MPI::Vector& x,
                         const dealii::PETScWrappers::MPI::Vector& b) {
  if (m_kind == Kind::iterative) {
    // Collective: every process meets the same KSP reason, so all of them switch together.
    try {
      return solve_iterative(K, x, b);
    } catch (const std::runtime_error& e) {
      if (!m_fall_back) throw;
      switch_to_direct(e.what());
    }
  }
  const MPI_Comm comm = K.get_mpi_communicator();
  if (!m_petsc) m_petsc = std::make_unique<Petsc>();
  if (!m_petsc->mumps) {
    // MUMPS: a parallel sparse LU (the tangent with contact need not be symmetric).
    check(KSPCreate(comm, &m_petsc->mumps), "KSPCreate");
    check(KSPSetType(m_petsc->mumps, KSPPREONLY), "KSPSetType");
    PC pc = nullptr;
    check(KSPGetPC(m_petsc->mumps, &pc), "KSPGetPC");
    check(PCSetType(pc, PCLU), "PCSetType");
    check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
    check(KSPSetFromOptions(m_petsc->mumps), "KSPSetFromOptions");
  }
  Mat A = static_cast<Mat>(K);
  check(KSPSetOperators(m_petsc->mumps, A, A), "KSPSetOperators");
  const auto [reason, iterations] = run_ksp(m_petsc->mumps, static_cast<const Vec&>(b), static_cast<const Vec&>(x),
                                               m_petsc_timings);
  if (reason < 0) throw_not_converged("MUMPS", reason, iterations);
  return 0;
}

int TangentSolver::solve_iterative(const dealii::PETScWrappers::MPI::SparseMatrix& K, dealii::PETScWrappers::MPI::Vector& x,
                                   const dealii::PETScWrappers::MPI::Vector& b) {
  const MPI_Comm comm = K.get_mpi_communicator();
  Mat A = static_cast<Mat>(K);
  PetscInt first = 0, last = 0;
  check(MatGetOwnershipRange(A, &first, &last), "MatGetOwnershipRange");
  if (!m_petsc) m_petsc = std::make_unique<Petsc>();
  if (!m_petsc->ksp) {
    // GAMG needs block size 3 for the rigid-body modes, which deal.II's matrix was created
    // without: a copy with block size 3 and the same rows (preallocated once, values every step).
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
    check(KSPCreate(comm, &m_petsc->ksp), "KSPCreate");
    configure_krylov_gamg(m_petsc->ksp, m_tolerance, m_spd, m_iterative.max_iterations);
  }
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
  if (m_iterative.rigid_body_modes) set_rigid_body_modes(m_petsc->A, comm, m_coordinates);
  check(KSPSetOperators(m_petsc->ksp, m_petsc->A, m_petsc->A), "KSPSetOperators");
  return run_iterative(static_cast<const Vec&>(b), static_cast<const Vec&>(x));
}

double distributed_cholesky_factor_entries(const dealii::DynamicSparsityPattern& pattern, const dealii::IndexSet& owned,
                                           MPI_Comm comm, double limit) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<std::int64_t> lengths, columns;
  for (const auto row : owned) {
    lengths.push_back(static_cast<std::int64_t>(pattern.row_length(row)));
    for (auto it = pattern.begin(row); it != pattern.end(row); ++it) columns.push_back(static_cast<std::int64_t>(it->column()));
  }
  const auto n = static_cast<std::size_t>(owned.size());
  long long local = static_cast<long long>(columns.size()), total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_LONG_LONG, MPI_SUM, comm);
  // L holds at least the lower triangle (n diagonal entries and half the others); the gather below
  // counts in int.
  if (0.5 * static_cast<double>(total + static_cast<long long>(n)) > limit || total > std::numeric_limits<int>::max())
    return std::numeric_limits<double>::infinity();
  // Rank r's rows follow rank r − 1's (deal.II numbers the processes' DOFs in rank order): each
  // process's first row says where its rows go.
  const long long first = owned.n_elements() > 0 ? static_cast<long long>(owned.nth_index_in_set(0)) : -1;
  const int my_rows = static_cast<int>(lengths.size()), my_entries = static_cast<int>(columns.size());
  std::vector<long long> firsts(static_cast<std::size_t>(size));
  std::vector<int> rows(static_cast<std::size_t>(size)), entries(static_cast<std::size_t>(size));
  MPI_Gather(&first, 1, MPI_LONG_LONG, firsts.data(), 1, MPI_LONG_LONG, 0, comm);
  MPI_Gather(&my_rows, 1, MPI_INT, rows.data(), 1, MPI_INT, 0, comm);
  MPI_Gather(&my_entries, 1, MPI_INT, entries.data(), 1, MPI_INT, 0, comm);
  std::vector<int> row_offset(static_cast<std::size_t>(size), 0), entry_offset(static_cast<std::size_t>(size), 0);
  std::vector<std::int64_t> all_lengths, all_columns;
  if (rank == 0) {
    for (int p = 1; p < size; ++p) {
      row_offset[static_cast<std::size_t>(p)] = row_offset[static_cast<std::size_t>(p - 1)] + rows[static_cast<std::size_t>(p - 1)];
      entry_offset[static_cast<std::size_t>(p)] =
          entry_offset[static_cast<std::size_t>(p - 1)] + entries[static_cast<std::size_t>(p - 1)];
    }
    all_lengths.resize(n);
    all_columns.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(lengths.data(), my_rows, MPI_INT64_T, all_lengths.data(), rows.data(), row_offset.data(), MPI_INT64_T, 0, comm);
  MPI_Gatherv(columns.data(), my_entries, MPI_INT64_T, all_columns.data(), entries.data(), entry_offset.data(), MPI_INT64_T,
              0, comm);
  double predicted = -1.0; // -1: the analysis failed on rank 0
  if (rank == 0) {
    bool in_order = true;
    for (int p = 0; p < size; ++p)
      if (rows[static_cast<std::size_t>(p)] > 0 && firsts[static_cast<std::size_t>(p)] != row_offset[static_cast<std::size_t>(p)])
        in_order = false;
    std::vector<std::int64_t> row_start{0};
    for (const auto l : all_lengths) row_start.push_back(row_start.back() + l);
    try {
      if (in_order) predicted = SparseDirect::predict_cholesky_factor_entries(n, row_start, all_columns);
    } catch (const std::exception&) {
      predicted = -1.0;
    }
  }
  MPI_Bcast(&predicted, 1, MPI_DOUBLE, 0, comm);
  if (predicted < 0.0)
    throw std::runtime_error("finite strain solver: CHOLMOD's analysis of the gathered distributed pattern failed "
                             "(or the processes' rows are not in rank order)");
  return predicted;
}

} // namespace kerf::reference
