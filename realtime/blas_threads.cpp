#include "realtime/blas_threads.hpp"

#include <dlfcn.h>

#include <atomic>
#include <mutex>

namespace kerf {

namespace {

int (*g_get_threads)() = nullptr;
void (*g_set_threads)(int) = nullptr;
std::atomic<int> g_users{0};
std::atomic<int> g_saved{1};

} // namespace

void find_blas_thread_calls() {
  static std::once_flag once;
  std::call_once(once, [] {
    g_get_threads = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    g_set_threads = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (!g_get_threads || !g_set_threads) g_get_threads = nullptr, g_set_threads = nullptr;
  });
}

bool limit_blas_to_one_thread() {
  find_blas_thread_calls();
  if (!g_set_threads) return false;
  g_set_threads(1);
  return true;
}

SingleThreadedBlas::SingleThreadedBlas() {
  if (!g_set_threads) return;
  if (g_users.fetch_add(1) == 0) {
    g_saved = g_get_threads();
    if (g_saved > 1) g_set_threads(1);
  }
}

SingleThreadedBlas::~SingleThreadedBlas() {
  if (!g_set_threads) return;
  if (g_users.fetch_sub(1) == 1 && g_saved > 1) g_set_threads(g_saved);
}

} // namespace kerf
