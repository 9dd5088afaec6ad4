#include "realtime/haptics/realtime_scheduling.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

namespace kerf {

bool set_fifo_priority(int priority) noexcept {
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

int last_of_several_cpus() noexcept {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (pthread_getaffinity_np(pthread_self(), sizeof set, &set) != 0 || CPU_COUNT(&set) < 2) return -1;
  for (int cpu = CPU_SETSIZE - 1; cpu >= 0; --cpu)
    if (CPU_ISSET(cpu, &set)) return cpu;
  return -1;
}

bool pin_to_cpu(int cpu) noexcept {
  if (cpu < 0 || cpu >= CPU_SETSIZE) return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

CpuMask keep_off_cpu(int cpu) noexcept {
  CpuMask before;
  if (cpu < 0 || cpu >= CPU_SETSIZE || pthread_getaffinity_np(pthread_self(), sizeof before.set, &before.set) != 0) return {};
  if (!CPU_ISSET(cpu, &before.set) || CPU_COUNT(&before.set) < 2) return {};
  cpu_set_t without = before.set;
  CPU_CLR(cpu, &without);
  before.saved = pthread_setaffinity_np(pthread_self(), sizeof without, &without) == 0;
  return before;
}

void restore_cpus(const CpuMask& mask) noexcept {
  if (mask.saved) pthread_setaffinity_np(pthread_self(), sizeof mask.set, &mask.set);
}

double thread_cpu_seconds() noexcept {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

RealtimeSetup enter_realtime(int priority, int cpu) noexcept {
  RealtimeSetup setup;
  try {
    if (cpu >= 0) {
      if (pin_to_cpu(cpu))
        setup.cpu = cpu;
      else
        setup.warnings += "warning: servo thread not pinned to CPU " + std::to_string(cpu) + "\n";
    }
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      setup.locked = true;
    } else {
      setup.warnings += std::string("warning: memory not locked (mlockall: ") + std::strerror(errno) +
                        "); page faults may delay the servo loop. Grant CAP_IPC_LOCK or raise `ulimit -l`.\n";
    }
    sched_param param{};
    param.sched_priority = priority;
    if (const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); e == 0) {
      setup.fifo = true;
    } else {
      setup.warnings += std::string("warning: servo thread not real-time (SCHED_FIFO priority ") +
                        std::to_string(priority) + ": " + std::strerror(e) +
                        "); it runs under the ordinary scheduler, expect larger jitter. Grant CAP_SYS_NICE or "
                        "raise `ulimit -r`.\n";
    }
  } catch (...) { // std::string allocation failure: report nothing rather than throw
  }
  return setup;
}

} // namespace kerf
