#pragma once
// Real-time scheduling for the servo thread: SCHED_FIFO priority and locked memory when the
// process is permitted (root, CAP_SYS_NICE/CAP_IPC_LOCK, or rtprio/memlock limits), otherwise
// the ordinary scheduler with a clear warning saying what was refused and why.

#include <string>

namespace kerf {

/// What enter_realtime obtained.
struct RealtimeSetup {
  bool fifo = false;      ///< the calling thread runs SCHED_FIFO at the requested priority
  bool locked = false;    ///< mlockall(MCL_CURRENT | MCL_FUTURE) succeeded (no page faults to disk)
  std::string warnings;   ///< empty when both succeeded; else one line per refusal, with errno text
};

/// Locks the process's memory and puts the calling thread under SCHED_FIFO at `priority`
/// (1..99). Never throws: a refusal is reported in the result.
RealtimeSetup enter_realtime(int priority) noexcept;

/// Sets the calling thread's SCHED_FIFO priority only (for a second real-time thread). Returns
/// false when refused.
bool set_fifo_priority(int priority) noexcept;

} // namespace kerf
