#include "experiments/study/blas_threads.hpp"

#include <dlfcn.h>

namespace kerf {

bool limit_blas_to_one_thread() {
  // OpenBLAS's C interface: void openblas_set_num_threads(int). Found in the process's global
  // scope when libblas.so.3 is OpenBLAS (deal.II and UMFPACK link it); absent otherwise.
  using SetThreads = void (*)(int);
  void* symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
  if (!symbol) return false;
  reinterpret_cast<SetThreads>(symbol)(1);
  return true;
}

} // namespace kerf
