#pragma once
// The threads of the BLAS under the reference's direct solver (UMFPACK calls the BLAS for its
// dense frontal matrices; Debian's libblas.so.3 is OpenBLAS with pthreads when
// libopenblas0-pthread is installed, as experiments/setup_and_run.sh does).

namespace kerf {

/// Limits OpenBLAS to one thread for the rest of the process, when the BLAS loaded is OpenBLAS
/// (looked up at run time, `openblas_set_num_threads`; another BLAS is left as it is). A study runs
/// its reference solves and fast models one per core (study_runner.hpp, StudyExecution): OpenBLAS's
/// own threads, one per core each, then compete with those runs for the same cores and spin while
/// they wait. Measured on potato_rect_cut's reference (P1, h = 2 mm, fracture on, 12 samples, 150
/// Newton iterations): 29.0 s user + 5.8 s system CPU with OpenBLAS's threads, 24.8 s + 0.1 s with
/// one (docs/studies.md). Returns whether the BLAS was OpenBLAS.
bool limit_blas_to_one_thread();

} // namespace kerf
