#pragma once
// OpenBLAS's thread count (Debian's default BLAS, openblas-pthread). OpenBLAS fans large BLAS calls
// out to its own thread pool, one thread per core: beside other work on the same cores (a study's
// parallel runs, a servo loop) those threads compete for the cores and spin while they wait, and
// the pool allocates per call. The calls are looked up at run time (`openblas_get_num_threads`,
// `openblas_set_num_threads` in the process's global scope): with another BLAS nothing changes.

namespace kerf {

/// Looks up OpenBLAS's thread-count calls, once per process (a later call does nothing). Call it
/// off the hot path, before the first SingleThreadedBlas.
void find_blas_thread_calls();

/// Limits OpenBLAS to one thread for the rest of the process. Returns whether the BLAS is OpenBLAS.
/// Measured on potato_rect_cut's reference (P1, h = 2 mm, fracture on, 12 samples): 29.0 s user +
/// 5.8 s system CPU with OpenBLAS's threads, 24.8 s + 0.1 s with one (docs/studies.md).
bool limit_blas_to_one_thread();

/// OpenBLAS on one thread for the scope (nothing with another BLAS, or before
/// find_blas_thread_calls). Lock-free and allocation-free: the pool is not resized. The count is
/// process-wide, so with several scopes at once (a study's parallel jobs) the first to enter sets
/// one thread and the last to leave restores the count.
class SingleThreadedBlas {
public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;
};

} // namespace kerf
