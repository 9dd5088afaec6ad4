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

RealtimeSetup enter_realtime(int priority) noexcept {
  RealtimeSetup setup;
  try {
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
