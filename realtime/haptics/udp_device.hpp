#pragma once
// `udp://HOST:PORT`: a device speaking kerf's device protocol (docs/device-protocol.md) at
// HOST:PORT. The rig's socket is connected to that address, so only that peer's datagrams are
// read; the device learns the rig's address from the first force command.

#include "realtime/haptics/haptic_device.hpp"

#include <array>
#include <cstdint>
#include <string>

namespace kerf {

class UdpDevice final : public HapticDevice {
public:
  /// Resolves HOST (numeric IPv4 or a name) and connects a non-blocking UDP socket to HOST:PORT.
  /// Throws std::invalid_argument naming the address on failure.
  UdpDevice(const std::string& host, int port);
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;

  [[nodiscard]] std::string_view address() const noexcept override { return m_address; }
  bool poll(double now) noexcept override;
  [[nodiscard]] bool has_state() const noexcept override { return m_has_state; }
  [[nodiscard]] const DeviceState& state() const noexcept override { return m_state; }
  void command(const Eigen::Vector3d& force, const Eigen::Vector3d& torque, std::uint32_t status,
               double now) noexcept override;
  [[nodiscard]] const LinkCounters& counters() const noexcept override { return m_counters; }
  /// Force commands that could not be sent (socket errors, e.g. the device's port closed).
  [[nodiscard]] std::uint64_t send_failures() const noexcept { return m_send_failures; }

private:
  std::string m_address;
  int m_socket = -1;
  DeviceState m_state;
  bool m_has_state = false;
  LinkCounters m_counters;
  SequenceFilter m_filter;
  std::uint32_t m_sequence = 0;
  std::uint64_t m_send_failures = 0;
  std::array<std::byte, 512> m_buffer{}; // larger than any packet, so oversized datagrams are seen whole
};

/// Monotonic clock reading in nanoseconds (CLOCK_MONOTONIC), the protocol's timestamp.
std::uint64_t monotonic_ns() noexcept;

} // namespace kerf
