// limit_blas_to_one_thread (realtime/blas_threads.hpp): with OpenBLAS loaded (Debian's
// libblas.so.3 when libopenblas0-pthread is installed, as experiments/setup_and_run.sh does) its
// own thread count reads 1 afterwards, whatever it was (one per core by default); with another
// BLAS the call says so and changes nothing.

#include "realtime/blas_threads.hpp"

#include <gtest/gtest.h>

#include <dlfcn.h>

TEST(BlasThreads, OpenBlasRunsOneThreadAfterwards) {
  using GetThreads = int (*)();
  void* get = dlsym(RTLD_DEFAULT, "openblas_get_num_threads");
  EXPECT_EQ(kerf::limit_blas_to_one_thread(), get != nullptr);
  if (get) {
    EXPECT_EQ(reinterpret_cast<GetThreads>(get)(), 1);
  }
}
