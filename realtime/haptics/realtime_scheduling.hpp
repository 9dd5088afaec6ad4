#pragma once
// Real-time scheduling for the servo thread: SCHED_FIFO priority and locked memory when the
// process is permitted (root, CAP_SYS_NICE/CAP_IPC_LOCK, or rtprio/memlock limits), otherwise
// the ordinary scheduler with a clear warning saying what was refused and why.

#include <sched.h>

#include <string>

namespace kerf {

/// What enter_realtime obtained.
struct RealtimeSetup {
  bool fifo = false;      ///< the calling thread runs SCHED_FIFO at the requested priority
  bool locked = false;    ///< mlockall(MCL_CURRENT | MCL_FUTURE) succeeded (no page faults to disk)
  int cpu = -1;           ///< the CPU the thread is pinned to (ServoSettings::cpu); -1: not pinned
  std::string warnings;   ///< empty when both succeeded; else one line per refusal, with errno text
};

/// Locks the process's memory and puts the calling thread under SCHED_FIFO at `priority`
/// (1..99), pinned to `cpu` when `cpu` >= 0. Never throws: a refusal is reported in the result.
RealtimeSetup enter_realtime(int priority, int cpu = -1) noexcept;

/// The highest-numbered CPU the calling thread may run on when it may run on at least two
/// (the one to give a real-time thread, the others left to the rest of the process); -1 when it
/// may run on one CPU only or the mask cannot be read.
int last_of_several_cpus() noexcept;

/// Pins the calling thread to `cpu` alone. Returns false when refused.
bool pin_to_cpu(int cpu) noexcept;

/// Keeps the calling thread (and the threads it starts afterwards, which inherit its mask) off
/// `cpu`, when it may run elsewhere too. Returns the mask it had, to restore_cpus at the end;
/// nothing changes when `cpu` < 0 or it is the thread's only CPU.
struct CpuMask {
  bool saved = false;
  cpu_set_t set{};
};
CpuMask keep_off_cpu(int cpu) noexcept;
void restore_cpus(const CpuMask& mask) noexcept;

/// CPU time the calling thread has used [s] (CLOCK_THREAD_CPUTIME_ID): a cost measure that a
/// preemption or a busy neighbour does not inflate.
double thread_cpu_seconds() noexcept;

/// Sets the calling thread's SCHED_FIFO priority only (for a second real-time thread). Returns
/// false when refused.
bool set_fifo_priority(int priority) noexcept;

} // namespace kerf
