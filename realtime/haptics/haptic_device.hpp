#pragma once
// A haptic device as the servo loop sees it (CHAI3D's cGenericHapticDevice split the kerf way):
// timestamped state reads (position, orientation, buttons), one command entry point (force,
// optionally torque), and its declared capabilities as plain data.

#include "realtime/haptics/device_protocol.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace kerf {

/// The newest state of a device.
struct DeviceState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< tool reference point [m]
  Eigen::Vector4d orientation{1.0, 0.0, 0.0, 0.0};     ///< unit quaternion (w, x, y, z)
  std::uint32_t buttons = 0;                           ///< bit k = button k; emergency_stop_button
  double max_force = 0.0;                              ///< the device's declared maximum force [N]
  std::uint32_t sequence = 0;                          ///< the device's sequence number of this state
  double received_time = 0.0;                          ///< rig clock when it arrived [s]
};

/// Interface of every device backend. poll() and command() are called from the servo thread:
/// they are noexcept and allocate nothing.
class HapticDevice {
public:
  virtual ~HapticDevice() = default;
  /// What the device was opened from ("udp://127.0.0.1:5000", "replay:FILE").
  [[nodiscard]] virtual std::string_view address() const noexcept = 0;
  /// Reads everything the device has sent since the last call; `now` is the rig clock [s].
  /// Returns true when a newer state was accepted.
  virtual bool poll(double now) noexcept = 0;
  /// True once a state has been accepted.
  [[nodiscard]] virtual bool has_state() const noexcept = 0;
  /// The newest accepted state (meaningful once has_state()).
  [[nodiscard]] virtual const DeviceState& state() const noexcept = 0;
  /// Sends the force [N] and torque [N m] to display, with SafetyStatus bits; `now` [s].
  virtual void command(const Eigen::Vector3d& force, const Eigen::Vector3d& torque, std::uint32_t status,
                       double now) noexcept = 0;
  /// Receive counters of the link (all zero for a backend without a link).
  [[nodiscard]] virtual const LinkCounters& counters() const noexcept = 0;
};

/// Opens a device from its address: `udp://HOST:PORT` (kerf's device protocol,
/// docs/device-protocol.md) or `replay:FILE` (a recorded or scripted trajectory, see
/// replay_device.hpp). Throws std::invalid_argument naming the address when it is malformed or
/// cannot be opened.
std::unique_ptr<HapticDevice> open_device(const std::string& address);

} // namespace kerf
