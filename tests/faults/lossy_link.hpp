#pragma once
// A lossy link for fault-injection tests of the haptic rig (docs/reliability.md): a UDP relay on loopback
// between the rig (a UdpDevice connected to the relay's port) and a device (DeviceEmulator). It
// forwards the rig's force commands to the device untouched, logging each one, and damages the
// device's state datagrams on their way to the rig: dropped, duplicated, reordered, truncated,
// held back and released in bursts (a stalled link), or cut off for good (a device that stops
// answering). Every decision comes from a seeded generator, so a run is reproducible up to the
// timing of the threads, and everything the link did is counted for the tests to compare with
// the rig's LinkCounters.

#include "realtime/haptics/device_protocol.hpp"

#include <Eigen/Core>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace kerf::test {

/// What the link does to each device-state datagram (probabilities in [0, 1], times in seconds).
struct LinkFaults {
  double drop = 0.0;          ///< dropped
  double duplicate = 0.0;     ///< sent twice, back to back
  double reorder = 0.0;       ///< held and sent right after the next datagram
  double truncate = 0.0;      ///< cut to a length drawn uniformly in [0, 87] bytes
  double stall_period = 0.0;  ///< > 0: every state is held and all are released together once per period
  double silent_after = -1.0; ///< >= 0: from this long after the first state on, nothing reaches the rig
  /// >= 0: from this long after the first state on, the device's clock has jumped: clock_jump_ns
  /// is added to every later state's timestamp (negative: backwards), the rest of it untouched.
  double clock_jump_after = -1.0;
  std::int64_t clock_jump_ns = 0;
  unsigned seed = 1;
};

/// One force command on its way to the device, as the link saw it.
struct RelayedCommand {
  double time = 0.0;                                ///< [s] since the link started
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< [N]
  std::uint32_t status = 0;                         ///< SafetyStatus bits
  std::uint32_t sequence = 0;                       ///< the rig's command sequence number
  std::uint64_t timestamp_ns = 0;                   ///< the rig's monotonic clock when sent
  std::uint32_t echo_sequence = 0;                  ///< the newest device state the rig had accepted
};

/// One device state sent on to the rig, as the device sent it (before any clock jump).
struct DeliveredState {
  std::uint32_t sequence = 0;
  std::uint64_t timestamp_ns = 0; ///< the device's monotonic clock when sent
};

/// What the link did (read after stop()).
struct LinkLog {
  std::uint64_t states = 0;       ///< state datagrams received from the device
  std::uint64_t delivered = 0;    ///< datagrams sent on to the rig (duplicates counted twice)
  std::uint64_t duplicated = 0;
  std::uint64_t reordered = 0;
  std::uint64_t truncated = 0;
  std::uint64_t stalls = 0;       ///< bursts released after a stall
  std::vector<std::uint32_t> dropped;   ///< sequence numbers dropped (not silenced)
  std::uint32_t first_delivered = 0;    ///< sequence of the first state the rig was sent
  double silenced_at = -1.0;            ///< [s] when the link went silent (< 0: never)
  std::uint32_t first_jumped = 0;       ///< sequence of the first state with a jumped clock (0: none)
  std::vector<DeliveredState> delivered_states; ///< every whole state passed on toward the rig, in order
  std::vector<RelayedCommand> commands; ///< every force command forwarded to the device
};

class LossyLink {
public:
  /// Binds the rig-facing socket on 127.0.0.1 (port() is where the rig connects) and a
  /// device-facing one that talks to 127.0.0.1:`device_port`, and starts the relay thread.
  LossyLink(int device_port, const LinkFaults& faults);
  ~LossyLink();
  LossyLink(const LossyLink&) = delete;
  LossyLink& operator=(const LossyLink&) = delete;

  [[nodiscard]] int port() const noexcept { return m_port; }
  /// Stops the relay thread; the log is complete afterwards.
  void stop();
  [[nodiscard]] const LinkLog& log() const noexcept { return m_log; }

private:
  void run();

  LinkFaults m_faults;
  int m_rig_socket = -1;
  int m_device_socket = -1;
  int m_port = 0;
  int m_device_port = 0;
  LinkLog m_log;
  std::atomic<bool> m_stop{false};
  std::thread m_thread;
};

} // namespace kerf::test
