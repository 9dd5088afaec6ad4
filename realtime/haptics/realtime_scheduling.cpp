#include "realtime/haptics/realtime_scheduling.hpp"

#include <cerrno>
#include <cstring>
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
  static_assert(sizeof(cpu_set_t) == sizeof(CpuMask::bits));
  CpuMask saved;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (cpu < 0 || cpu >= CPU_SETSIZE || pthread_getaffinity_np(pthread_self(), sizeof set, &set) != 0) return saved;
  if (!CPU_ISSET(cpu, &set) || CPU_COUNT(&set) < 2) return saved;
  std::memcpy(saved.bits, &set, sizeof set);
  CPU_CLR(cpu, &set);
  saved.saved = pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
  return saved;
}

void restore_cpus(const CpuMask& mask) noexcept {
  if (!mask.saved) return;
  cpu_set_t set;
  std::memcpy(&set, mask.bits, sizeof set);
  pthread_setaffinity_np(pthread_self(), sizeof set, &set);
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
