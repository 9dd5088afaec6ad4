#include "reference/sparse_direct.hpp"
#include "meshes/c_random_generator.hpp"

#include <cholmod.h>
#include <dlfcn.h>
#include <umfpack.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>
#include <stdexcept>

namespace kerf::reference {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// CHOLMOD 3 (SuiteSparse 5) opens the OpenMP loops of its supernodal factorisation with
/// num_threads(CHOLMOD_OMP_NUM_THREADS), 4 compiled in, whatever OMP_NUM_THREADS says. Those loops
/// clear, copy and scatter-add entry by entry (the arithmetic is BLAS's), so their threads mostly
/// spin and wait: on two shared cores they cost 15–20 % of the CPU time of Cook's membrane at 2 mm
/// (docs/reference.md, "Where the time goes"). While an object of this class lives, OpenMP's
/// max-active-levels is 0, so that every parallel region runs on the thread that meets it (the
/// OpenMP specification's rule for a team's size: one thread once the active levels reach
/// max-active-levels). The loops write disjoint entries, each computed the same way on any
/// thread, so the factor does not depend on the thread count. The OpenMP runtime is looked up,
/// not linked: without one (a CHOLMOD built without OpenMP) there is nothing to do.
class SerialOpenMP {
public:
  // Reference solves may run on several threads at once (a study's tasks): the first one in saves
  // the level and the last one out restores it. Every one sets 0, for a runtime that keeps the
  // level per thread.
  SerialOpenMP() {
    const Runtime& r = runtime();
    if (r.get == nullptr || r.set == nullptr) return;
    const std::lock_guard lock(shared().mutex);
    if (shared().users++ == 0) shared().saved = r.get();
    r.set(0);
    m_active = true;
  }
  ~SerialOpenMP() {
    if (!m_active) return;
    const std::lock_guard lock(shared().mutex);
    if (--shared().users == 0) runtime().set(shared().saved);
  }
  SerialOpenMP(const SerialOpenMP&) = delete;
  SerialOpenMP& operator=(const SerialOpenMP&) = delete;

private:
  struct Runtime {
    int (*get)() = nullptr;
    void (*set)(int) = nullptr;
  };
  struct Shared {
    std::mutex mutex;
    int users = 0;
    int saved = 0;
  };
  static const Runtime& runtime() {
    static const Runtime r{reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels")),
                           reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"))};
    return r;
  }
  static Shared& shared() {
    static Shared s;
    return s;
  }
  bool m_active = false;
};

} // namespace

/// CHOLMOD's supernodal Cholesky of the lower triangle, stored column by column (CSC): column j
/// holds the rows i >= j, which for a symmetric K are row j's entries K_jc with c >= j.
struct SparseDirect::Cholmod {
  cholmod_common common{};
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  std::vector<std::int64_t> source; ///< CSC entry k -> the pattern's entry it takes its value from
  Cholmod() {
    cholmod_l_start(&common);
    common.quick_return_if_not_posdef = 1; // a failed factorisation stops at the first bad pivot
    // Always the supernodal L Lᵀ: CHOLMOD's simplicial LDLᵀ (its choice for small, sparse factors)
    // would factorise an indefinite matrix without pivoting instead of reporting it.
    common.supernodal = CHOLMOD_SUPERNODAL;
    // A matrix that is not positive definite is an expected answer here (the LU takes over, and
    // the counters record it), not a warning to print on stderr at every Newton iteration.
    common.print = 0;
    common.error_handler = nullptr;
  }
  ~Cholmod() {
    if (L) cholmod_l_free_factor(&L, &common);
    if (A) cholmod_l_free_sparse(&A, &common);
    cholmod_l_finish(&common);
  }
};

/// UMFPACK's LU of K, given as Kᵀ in compressed columns (that is K's compressed rows, each sorted)
/// and solved with the transposed system; the symbolic analysis is kept.
struct SparseDirect::Umfpack {
  std::vector<SuiteSparse_long> Ap, Ai;
  std::vector<double> Ax;
  std::vector<std::int64_t> source; ///< sorted entry k -> the pattern's entry
  void* symbolic = nullptr;
  void* numeric = nullptr;
  double control[UMFPACK_CONTROL];
  Umfpack() { umfpack_dl_defaults(control); }
  ~Umfpack() {
    if (numeric) umfpack_dl_free_numeric(&numeric);
    if (symbolic) umfpack_dl_free_symbolic(&symbolic);
  }
};

SparseDirect::SparseDirect(std::size_t n, std::vector<std::int64_t> row_start, std::vector<std::int64_t> columns)
    : m_n(n), m_row_start(std::move(row_start)), m_columns(std::move(columns)) {
  if (m_row_start.size() != n + 1 || m_row_start.back() != static_cast<std::int64_t>(m_columns.size()))
    throw std::invalid_argument("SparseDirect: the row starts do not describe " + std::to_string(n) + " rows of " +
                                std::to_string(m_columns.size()) + " entries");
  // The transpose map: entry (i, j) -> entry (j, i), by a search in row j (its columns sorted once).
  std::vector<std::vector<std::pair<std::int64_t, std::int64_t>>> rows(n); // (column, entry), sorted
  for (std::size_t r = 0; r < n; ++r) {
    for (std::int64_t e = m_row_start[r]; e < m_row_start[r + 1]; ++e) rows[r].emplace_back(m_columns[static_cast<std::size_t>(e)], e);
    std::sort(rows[r].begin(), rows[r].end());
  }
  m_transpose.assign(m_columns.size(), -1);
  for (std::size_t r = 0; r < n; ++r)
    for (const auto& [c, e] : rows[r]) {
      const auto& row_c = rows[static_cast<std::size_t>(c)];
      const auto it = std::lower_bound(row_c.begin(), row_c.end(), std::make_pair(static_cast<std::int64_t>(r), std::int64_t{-1}));
      if (it != row_c.end() && it->first == static_cast<std::int64_t>(r)) m_transpose[static_cast<std::size_t>(e)] = it->second;
    }
}

SparseDirect::~SparseDirect() = default;

std::string SparseDirect::last_method() const { return m_last_cholesky ? "cholmod" : "umfpack"; }

bool SparseDirect::symmetric(const std::vector<double>& values) const {
  double largest = 0.0;
  for (const double v : values) largest = std::max(largest, std::abs(v));
  const double tolerance = 1e-12 * largest;
  for (std::size_t e = 0; e < values.size(); ++e) {
    const std::int64_t t = m_transpose[e];
    const double other = t < 0 ? 0.0 : values[static_cast<std::size_t>(t)];
    if (!(std::abs(values[e] - other) <= tolerance)) return false; // also false on a NaN
  }
  return true;
}

void SparseDirect::factorize(const std::vector<double>& values) {
  if (values.size() != m_columns.size())
    throw std::invalid_argument("SparseDirect::factorize: " + std::to_string(values.size()) + " values for a pattern of " +
                                std::to_string(m_columns.size()) + " entries");
  if (symmetric(values) && factorize_cholesky(values)) {
    m_last_cholesky = true;
    return;
  }
  factorize_lu(values);
  m_last_cholesky = false;
}

double SparseDirect::cholesky_factor_entries() {
  analyze_cholesky();
  return m_cholmod->common.lnz;
}

namespace {

/// The lower triangle of a symmetric pattern in compressed columns, as CHOLMOD takes it: column j
/// holds row j's columns c >= j (sorted); `source[k]` = the pattern entry of CSC entry k.
struct LowerColumns {
  std::vector<std::int64_t> col_start{0}, row_index, source;
};

LowerColumns lower_columns(std::size_t n, const std::vector<std::int64_t>& row_start, const std::vector<std::int64_t>& columns) {
  LowerColumns out;
  std::vector<std::pair<std::int64_t, std::int64_t>> entries; // (row, source) of one column
  for (std::size_t j = 0; j < n; ++j) {
    entries.clear();
    for (std::int64_t e = row_start[j]; e < row_start[j + 1]; ++e)
      if (columns[static_cast<std::size_t>(e)] >= static_cast<std::int64_t>(j)) entries.emplace_back(columns[static_cast<std::size_t>(e)], e);
    std::sort(entries.begin(), entries.end());
    for (const auto& [i, e] : entries) {
      out.row_index.push_back(i);
      out.source.push_back(e);
    }
    out.col_start.push_back(static_cast<std::int64_t>(out.row_index.size()));
  }
  return out;
}

/// CHOLMOD's symbolic analysis (fill-reducing ordering, supernodal structure) of `A`'s pattern.
cholmod_factor* analyze(cholmod_sparse* A, cholmod_common& common) {
  const SerialOpenMP serial;
  // METIS, among the orderings the analysis tries, seeds and draws from the C library's rand(),
  // which gmsh uses too (meshes/c_random_generator.hpp).
  const std::lock_guard<std::mutex> random(c_random_generator_mutex());
  return cholmod_l_analyze(A, &common);
}
} // namespace

void SparseDirect::analyze_cholesky() {
  if (!m_cholmod) {
    const auto t0 = Clock::now();
    m_cholmod = std::make_unique<Cholmod>();
    Cholmod& c = *m_cholmod;
    LowerColumns lower = lower_columns(m_n, m_row_start, m_columns);
    c.source = std::move(lower.source);
    c.A = cholmod_l_allocate_sparse(m_n, m_n, lower.row_index.size(), 1, 1, -1, CHOLMOD_REAL, &c.common);
    if (c.A == nullptr) throw std::runtime_error("SparseDirect: CHOLMOD could not allocate the matrix");
    std::copy(lower.col_start.begin(), lower.col_start.end(), static_cast<SuiteSparse_long*>(c.A->p));
    std::copy(lower.row_index.begin(), lower.row_index.end(), static_cast<SuiteSparse_long*>(c.A->i));
    c.L = analyze(c.A, c.common);
    if (c.L == nullptr || c.common.status < CHOLMOD_OK)
      throw std::runtime_error("SparseDirect: CHOLMOD's analysis failed (status " + std::to_string(c.common.status) + ")");
    m_counters.analysis_seconds += seconds_since(t0);
  }
}

double SparseDirect::predict_cholesky_factor_entries(std::size_t n, const std::vector<std::int64_t>& row_start,
                                                     const std::vector<std::int64_t>& columns) {
  if (row_start.size() != n + 1 || row_start.back() != static_cast<std::int64_t>(columns.size()))
    throw std::invalid_argument("SparseDirect: the row starts do not describe " + std::to_string(n) + " rows of " +
                                std::to_string(columns.size()) + " entries");
  Cholmod c; // its settings (supernodal) are the factorisation's
  const LowerColumns lower = lower_columns(n, row_start, columns);
  c.A = cholmod_l_allocate_sparse(n, n, lower.row_index.size(), 1, 1, -1, CHOLMOD_PATTERN, &c.common);
  if (c.A == nullptr) throw std::runtime_error("SparseDirect: CHOLMOD could not allocate the pattern");
  std::copy(lower.col_start.begin(), lower.col_start.end(), static_cast<SuiteSparse_long*>(c.A->p));
  std::copy(lower.row_index.begin(), lower.row_index.end(), static_cast<SuiteSparse_long*>(c.A->i));
  c.L = analyze(c.A, c.common);
  if (c.L == nullptr || c.common.status < CHOLMOD_OK)
    throw std::runtime_error("SparseDirect: CHOLMOD's analysis failed (status " + std::to_string(c.common.status) + ")");
  return c.common.lnz;
}

bool SparseDirect::factorize_cholesky(const std::vector<double>& values) {
  analyze_cholesky();
  Cholmod& c = *m_cholmod;
  const auto t0 = Clock::now();
  auto* x = static_cast<double*>(c.A->x);
  for (std::size_t k = 0; k < c.source.size(); ++k) x[k] = values[static_cast<std::size_t>(c.source[k])];
  {
    const SerialOpenMP serial;
    cholmod_l_factorize(c.A, c.L, &c.common);
  }
  m_counters.factorization_seconds += seconds_since(t0);
  if (c.common.status == CHOLMOD_NOT_POSDEF || c.L->minor < m_n) {
    ++m_counters.not_positive_definite;
    return false;
  }
  if (c.common.status < CHOLMOD_OK)
    throw std::runtime_error("SparseDirect: CHOLMOD's factorisation failed (status " + std::to_string(c.common.status) + ")");
  ++m_counters.cholesky;
  return true;
}

void SparseDirect::factorize_lu(const std::vector<double>& values) {
  if (!m_umfpack) {
    const auto t0 = Clock::now();
    m_umfpack = std::make_unique<Umfpack>();
    Umfpack& u = *m_umfpack;
    std::vector<std::pair<std::int64_t, std::int64_t>> entries;
    u.Ap.push_back(0);
    for (std::size_t r = 0; r < m_n; ++r) {
      entries.clear();
      for (std::int64_t e = m_row_start[r]; e < m_row_start[r + 1]; ++e) entries.emplace_back(m_columns[static_cast<std::size_t>(e)], e);
      std::sort(entries.begin(), entries.end());
      for (const auto& [col, e] : entries) {
        u.Ai.push_back(col);
        u.source.push_back(e);
      }
      u.Ap.push_back(static_cast<SuiteSparse_long>(u.Ai.size()));
    }
    u.Ax.resize(u.Ai.size());
    for (std::size_t k = 0; k < u.source.size(); ++k) u.Ax[k] = values[static_cast<std::size_t>(u.source[k])];
    const auto n = static_cast<SuiteSparse_long>(m_n);
    // The pattern alone (no values): the analysis must not depend on which matrix came first.
    // CHOLMOD's fill-reducing ordering of the pattern (the best of AMD and METIS, kept from the
    // Cholesky analysis) is given to UMFPACK with its symmetric strategy, which pivots on the
    // diagonal where the pivot is large enough (UMFPACK_SYM_PIVOT_TOLERANCE) and so keeps that
    // ordering: on the potato's symmetric indefinite tangents (40 002 DOFs) the LU then needs
    // about twice the Cholesky factor's entries and flops, where UMFPACK's own ordering needed
    // four and seven times them.
    analyze_cholesky();
    const auto* ordering = static_cast<const SuiteSparse_long*>(m_cholmod->L->Perm);
    u.control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC;
    u.control[UMFPACK_ORDERING] = UMFPACK_ORDERING_GIVEN;
    const SuiteSparse_long status =
        umfpack_dl_qsymbolic(n, n, u.Ap.data(), u.Ai.data(), nullptr, ordering, &u.symbolic, u.control, nullptr);
    if (status != UMFPACK_OK)
      throw std::runtime_error("SparseDirect: UMFPACK's symbolic analysis failed (status " + std::to_string(status) + ")");
    m_counters.analysis_seconds += seconds_since(t0);
  }
  Umfpack& u = *m_umfpack;
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < u.source.size(); ++k) u.Ax[k] = values[static_cast<std::size_t>(u.source[k])];
  if (u.numeric) umfpack_dl_free_numeric(&u.numeric);
  const SuiteSparse_long status = umfpack_dl_numeric(u.Ap.data(), u.Ai.data(), u.Ax.data(), u.symbolic, &u.numeric, u.control, nullptr);
  m_counters.factorization_seconds += seconds_since(t0);
  if (status != UMFPACK_OK)
    throw std::runtime_error("SparseDirect: UMFPACK's factorisation failed (status " + std::to_string(status) +
                             (status == UMFPACK_WARNING_singular_matrix ? ": singular matrix)" : ")"));
  ++m_counters.lu;
}

void SparseDirect::solve(const double* b, double* x) const {
  const auto t0 = Clock::now();
  if (m_last_cholesky) {
    Cholmod& c = *m_cholmod;
    cholmod_dense B{};
    B.nrow = m_n;
    B.ncol = 1;
    B.nzmax = m_n;
    B.d = m_n;
    B.x = const_cast<double*>(b);
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* X = nullptr;
    {
      const SerialOpenMP serial;
      X = cholmod_l_solve(CHOLMOD_A, c.L, &B, &c.common);
    }
    if (X == nullptr) throw std::runtime_error("SparseDirect: CHOLMOD's solve failed");
    std::copy_n(static_cast<const double*>(X->x), m_n, x);
    cholmod_l_free_dense(&X, &c.common);
  } else {
    const Umfpack& u = *m_umfpack;
    // The arrays hold Kᵀ column by column: K x = b is the transposed system of the stored matrix.
    const SuiteSparse_long status = umfpack_dl_solve(UMFPACK_At, u.Ap.data(), u.Ai.data(), u.Ax.data(), x, b, u.numeric,
                                                     u.control, nullptr);
    if (status != UMFPACK_OK && status != UMFPACK_WARNING_singular_matrix)
      throw std::runtime_error("SparseDirect: UMFPACK's solve failed (status " + std::to_string(status) + ")");
  }
  ++m_counters.solves;
  m_counters.solve_seconds += seconds_since(t0);
}

} // namespace kerf::reference
