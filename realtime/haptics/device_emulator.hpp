#pragma once
// An emulated device speaking kerf's device protocol (docs/device-protocol.md) from the device
// side, for `kerf-rig device-sim` and the loopback tests: it listens on a UDP port, runs a
// SimulatedHand following a target trajectory under the forces the rig commands, sends its
// state at a fixed rate to the rig (whose address it learns from the rig's commands), and
// records every force command it accepted.

#include "realtime/haptics/device_protocol.hpp"
#include "realtime/haptics/device_specs.hpp"
#include "realtime/haptics/simulated_hand.hpp"

#include <Eigen/Core>

#include <atomic>
#include <string>
#include <vector>

namespace kerf {

/// Settings of one emulated device.
struct EmulatedDeviceSettings {
  std::string host = "127.0.0.1";  ///< address to bind (loopback by default)
  int port = 0;                    ///< UDP port; 0 picks a free one (see DeviceEmulator::port())
  double rate = 1000.0;            ///< state packets per second and hand integration rate [Hz]
  /// Declared maximum force [N]. Default: the default device's (device_table, 8.5 N for the
  /// PHANToM Premium 1.5, a common research device).
  double max_force = device_specs_constexpr(default_device_model).max_force;
  HandParameters hand;
  std::vector<Eigen::Vector3d> target;  ///< target positions [m] sampled at target_rate
  double target_rate = 1000.0;          ///< [Hz]
  double hold = 0.5;    ///< [s] the hand waits at the start this long after the rig's first command
  double tail = 0.5;    ///< [s] it stays at the end this long before the emulator stops
  double command_timeout = 0.1; ///< [s] a force older than this is no longer applied (device-side watchdog)
  double emergency_stop_at = -1.0; ///< [s] after the first command, press the e-stop button (< 0: never)
};

/// One accepted force command, as the device received it.
struct ReceivedForce {
  double time = 0.0;                                 ///< [s] since the emulator started
  std::uint32_t sequence = 0;
  std::uint32_t status = 0;                          ///< SafetyStatus bits
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< [N]
  Eigen::Vector3d hand = Eigen::Vector3d::Zero();    ///< hand position when it arrived [m]
};

class DeviceEmulator {
public:
  /// Binds the socket (throws std::runtime_error naming host:port on failure) and checks the
  /// settings (std::invalid_argument: empty target, non-positive rates).
  explicit DeviceEmulator(const EmulatedDeviceSettings& settings);
  ~DeviceEmulator();
  DeviceEmulator(const DeviceEmulator&) = delete;
  DeviceEmulator& operator=(const DeviceEmulator&) = delete;

  /// The bound UDP port.
  [[nodiscard]] int port() const noexcept { return m_port; }
  /// Runs until the trajectory (plus hold and tail) is done after the rig's first command, or
  /// `stop` becomes true. Blocking; call from its own thread. Closes the socket at the end, so
  /// the link falls silent.
  void run(const std::atomic<bool>& stop);

  [[nodiscard]] const std::vector<ReceivedForce>& received() const noexcept { return m_received; }
  [[nodiscard]] const LinkCounters& counters() const noexcept { return m_counters; }
  /// Total duration of the hand's motion: hold + trajectory + tail [s].
  [[nodiscard]] double motion_duration() const noexcept;

private:
  EmulatedDeviceSettings m_settings;
  int m_socket = -1;
  int m_port = 0;
  std::vector<ReceivedForce> m_received;
  LinkCounters m_counters;
};

} // namespace kerf
