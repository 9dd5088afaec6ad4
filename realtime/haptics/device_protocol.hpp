#pragma once
// kerf's device protocol (docs/device-protocol.md): versioned little-endian UDP datagrams with
// sequence numbers and timestamps, in both directions. A device (or a bridge beside a vendor SDK,
// or `kerf-rig device-sim`) sends DeviceStatePacket; the rig answers with ForceCommandPacket. This
// file is the byte layout and the checks every received datagram passes before it is used.

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace kerf {

/// The four bytes every packet starts with: "KERF".
inline constexpr std::array<std::uint8_t, 4> device_protocol_magic{'K', 'E', 'R', 'F'};
/// The protocol version this build speaks; a packet with another version is dropped and counted.
inline constexpr std::uint16_t device_protocol_version = 1;

/// Packet types (header field `type`).
enum class PacketType : std::uint16_t { device_state = 1, force_command = 2 };

/// Header: magic[4] version:u16 type:u16 sequence:u32 timestamp_ns:u64 = 20 bytes.
inline constexpr std::size_t packet_header_size = 20;
/// Device state: header + position 3 f64 + orientation (w,x,y,z) 4 f64 + buttons u32 +
/// max_force f64 = 88 bytes.
inline constexpr std::size_t device_state_packet_size = packet_header_size + 24 + 32 + 4 + 8;
/// Force command: header + echo_sequence u32 + status u32 + force 3 f64 + torque 3 f64 = 76 bytes.
inline constexpr std::size_t force_command_packet_size = packet_header_size + 4 + 4 + 24 + 24;

/// Button bit a device sets while its emergency-stop switch is pressed (docs/device-protocol.md).
inline constexpr std::uint32_t emergency_stop_button = 1u << 31;

/// Status bits of a force command: what the rig's safety layer is doing (docs/device-protocol.md).
enum SafetyStatus : std::uint32_t {
  safety_ramping = 1u << 0,        ///< ramp in or out in progress (gain below 1)
  safety_clamped = 1u << 1,        ///< the force was clamped to the maximum
  safety_rate_limited = 1u << 2,   ///< the force-rate limit acted
  safety_non_finite = 1u << 3,     ///< the model returned NaN/Inf; replaced by zero
  safety_watchdog = 1u << 4,       ///< the link was silent too long: zero force
  safety_emergency_stop = 1u << 5, ///< emergency stop latched: zero force
  safety_stopped = 1u << 6,        ///< ramp out finished: zero force
  safety_waiting = 1u << 7,        ///< no device state yet: zero force
};

/// Device to rig: the device's pose and buttons at `timestamp_ns` (the device's monotonic clock).
struct DeviceStatePacket {
  std::uint32_t sequence = 0;
  std::uint64_t timestamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();          ///< tool reference point [m]
  Eigen::Vector4d orientation{1.0, 0.0, 0.0, 0.0};             ///< unit quaternion (w, x, y, z)
  std::uint32_t buttons = 0;                                   ///< bit k = button k pressed
  double max_force = 0.0;                                      ///< the device's declared maximum force [N]
};

/// Rig to device: the force (and torque) to display, in the device's frame.
struct ForceCommandPacket {
  std::uint32_t sequence = 0;
  std::uint64_t timestamp_ns = 0;      ///< the rig's monotonic clock when sent
  std::uint32_t echo_sequence = 0;     ///< sequence of the last device state the rig accepted
  std::uint32_t status = 0;            ///< SafetyStatus bits
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< [N]
  Eigen::Vector3d torque = Eigen::Vector3d::Zero(); ///< [N m]
};

/// Why a datagram could not be decoded.
enum class DecodeError { none, wrong_size, bad_magic, unsupported_version, wrong_type, invalid_value };

/// Writes the packet into `out` (exactly device_state_packet_size bytes). Returns the size.
std::size_t encode(const DeviceStatePacket& p, std::span<std::byte, device_state_packet_size> out) noexcept;
/// Writes the packet into `out` (exactly force_command_packet_size bytes). Returns the size.
std::size_t encode(const ForceCommandPacket& p, std::span<std::byte, force_command_packet_size> out) noexcept;

/// Decodes a device-state datagram. Checks, in order: size (exactly 88 bytes), magic, version,
/// type, then values (finite position and max_force >= 0, a finite orientation within 1e-3 of
/// unit norm). `out` is written only when the result is DecodeError::none.
DecodeError decode(std::span<const std::byte> datagram, DeviceStatePacket& out) noexcept;
/// Decodes a force-command datagram: size (76 bytes), magic, version, type, finite force and torque.
DecodeError decode(std::span<const std::byte> datagram, ForceCommandPacket& out) noexcept;

/// Per-link counts of received datagrams (what was used and why the rest was dropped).
struct LinkCounters {
  std::uint64_t received = 0;            ///< datagrams read from the socket
  std::uint64_t accepted = 0;            ///< decoded and newer than everything before
  std::uint64_t malformed = 0;           ///< wrong size, magic, type or a non-finite / invalid value
  std::uint64_t unsupported_version = 0; ///< a version other than device_protocol_version
  std::uint64_t duplicated = 0;          ///< same sequence as an accepted packet
  std::uint64_t stale = 0;               ///< older than the newest accepted (reordered or late)
  std::uint64_t lost = 0;                ///< sequence numbers skipped between accepted packets
  /// Every received datagram is either accepted or dropped for exactly one reason.
  [[nodiscard]] std::uint64_t dropped() const { return malformed + unsupported_version + duplicated + stale; }
};

/// Keeps only packets newer than the newest accepted one. Sequence numbers are compared in
/// serial-number arithmetic (RFC 1982, 32 bits): `a` is newer than `b` when the signed 32-bit
/// difference a - b is positive, so the counter may wrap. A packet whose sequence is newer but
/// whose timestamp is older than the newest accepted one is stale as well (a sender restarted
/// its clock but not its counter cannot move time backwards).
class SequenceFilter {
public:
  enum class Verdict { accept, duplicate, stale };
  /// Classifies the packet and, when accepted, remembers it; updates `counters` (accepted,
  /// duplicated, stale, lost).
  Verdict admit(std::uint32_t sequence, std::uint64_t timestamp_ns, LinkCounters& counters) noexcept;
  /// Forget the history (a new session).
  void reset() noexcept { m_any = false; }

private:
  bool m_any = false;
  std::uint32_t m_sequence = 0;
  std::uint64_t m_timestamp_ns = 0;
};

/// Decodes one received device-state datagram and passes it through the filter, counting it in
/// `counters` exactly once. Returns true (and fills `out`) when it is the newest valid state.
bool receive_device_state(std::span<const std::byte> datagram, SequenceFilter& filter, LinkCounters& counters,
                          DeviceStatePacket& out) noexcept;
/// The same for force commands (the device side).
bool receive_force_command(std::span<const std::byte> datagram, SequenceFilter& filter, LinkCounters& counters,
                           ForceCommandPacket& out) noexcept;

} // namespace kerf
