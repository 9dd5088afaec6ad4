#include "realtime/haptics/device_protocol.hpp"

#include <bit>
#include <cmath>
#include <cstring>

namespace kerf {

namespace {

// Little-endian field writers and readers, independent of the host's byte order.
template <typename U>
void put_uint(std::byte* at, U value) noexcept {
  for (std::size_t k = 0; k < sizeof(U); ++k) at[k] = static_cast<std::byte>((value >> (8 * k)) & 0xFFu);
}
template <typename U>
U get_uint(const std::byte* at) noexcept {
  U value = 0;
  for (std::size_t k = 0; k < sizeof(U); ++k) value |= static_cast<U>(std::to_integer<U>(at[k])) << (8 * k);
  return value;
}
void put_f64(std::byte* at, double v) noexcept { put_uint(at, std::bit_cast<std::uint64_t>(v)); }
double get_f64(const std::byte* at) noexcept { return std::bit_cast<double>(get_uint<std::uint64_t>(at)); }

void put_header(std::byte* at, PacketType type, std::uint32_t sequence, std::uint64_t timestamp_ns) noexcept {
  std::memcpy(at, device_protocol_magic.data(), 4);
  put_uint<std::uint16_t>(at + 4, device_protocol_version);
  put_uint<std::uint16_t>(at + 6, static_cast<std::uint16_t>(type));
  put_uint<std::uint32_t>(at + 8, sequence);
  put_uint<std::uint64_t>(at + 12, timestamp_ns);
}

DecodeError check_header(std::span<const std::byte> d, std::size_t size, PacketType type) noexcept {
  if (d.size() != size) return DecodeError::wrong_size;
  if (std::memcmp(d.data(), device_protocol_magic.data(), 4) != 0) return DecodeError::bad_magic;
  if (get_uint<std::uint16_t>(d.data() + 4) != device_protocol_version) return DecodeError::unsupported_version;
  if (get_uint<std::uint16_t>(d.data() + 6) != static_cast<std::uint16_t>(type)) return DecodeError::wrong_type;
  return DecodeError::none;
}

void count_error(DecodeError e, LinkCounters& c) noexcept {
  if (e == DecodeError::unsupported_version) ++c.unsupported_version;
  else ++c.malformed;
}

} // namespace

std::size_t encode(const DeviceStatePacket& p, std::span<std::byte, device_state_packet_size> out) noexcept {
  std::byte* b = out.data();
  put_header(b, PacketType::device_state, p.sequence, p.timestamp_ns);
  std::byte* at = b + packet_header_size;
  for (int k = 0; k < 3; ++k, at += 8) put_f64(at, p.position[k]);
  for (int k = 0; k < 4; ++k, at += 8) put_f64(at, p.orientation[k]);
  put_uint<std::uint32_t>(at, p.buttons);
  put_f64(at + 4, p.max_force);
  return device_state_packet_size;
}

std::size_t encode(const ForceCommandPacket& p, std::span<std::byte, force_command_packet_size> out) noexcept {
  std::byte* b = out.data();
  put_header(b, PacketType::force_command, p.sequence, p.timestamp_ns);
  std::byte* at = b + packet_header_size;
  put_uint<std::uint32_t>(at, p.echo_sequence);
  put_uint<std::uint32_t>(at + 4, p.status);
  at += 8;
  for (int k = 0; k < 3; ++k, at += 8) put_f64(at, p.force[k]);
  for (int k = 0; k < 3; ++k, at += 8) put_f64(at, p.torque[k]);
  return force_command_packet_size;
}

DecodeError decode(std::span<const std::byte> d, DeviceStatePacket& out) noexcept {
  if (const DecodeError e = check_header(d, device_state_packet_size, PacketType::device_state); e != DecodeError::none)
    return e;
  DeviceStatePacket p;
  p.sequence = get_uint<std::uint32_t>(d.data() + 8);
  p.timestamp_ns = get_uint<std::uint64_t>(d.data() + 12);
  const std::byte* at = d.data() + packet_header_size;
  for (int k = 0; k < 3; ++k, at += 8) p.position[k] = get_f64(at);
  for (int k = 0; k < 4; ++k, at += 8) p.orientation[k] = get_f64(at);
  p.buttons = get_uint<std::uint32_t>(at);
  p.max_force = get_f64(at + 4);
  if (!p.position.allFinite() || !p.orientation.allFinite() || !std::isfinite(p.max_force) || p.max_force < 0.0)
    return DecodeError::invalid_value;
  // A unit quaternion within 1e-3 (a double-precision device sends it normalised).
  if (std::abs(p.orientation.norm() - 1.0) > 1e-3) return DecodeError::invalid_value;
  out = p;
  return DecodeError::none;
}

DecodeError decode(std::span<const std::byte> d, ForceCommandPacket& out) noexcept {
  if (const DecodeError e = check_header(d, force_command_packet_size, PacketType::force_command);
      e != DecodeError::none)
    return e;
  ForceCommandPacket p;
  p.sequence = get_uint<std::uint32_t>(d.data() + 8);
  p.timestamp_ns = get_uint<std::uint64_t>(d.data() + 12);
  const std::byte* at = d.data() + packet_header_size;
  p.echo_sequence = get_uint<std::uint32_t>(at);
  p.status = get_uint<std::uint32_t>(at + 4);
  at += 8;
  for (int k = 0; k < 3; ++k, at += 8) p.force[k] = get_f64(at);
  for (int k = 0; k < 3; ++k, at += 8) p.torque[k] = get_f64(at);
  if (!p.force.allFinite() || !p.torque.allFinite()) return DecodeError::invalid_value;
  out = p;
  return DecodeError::none;
}

SequenceFilter::Verdict SequenceFilter::admit(std::uint32_t sequence, std::uint64_t timestamp_ns,
                                              LinkCounters& counters) noexcept {
  if (m_any) {
    // RFC 1982 serial-number comparison: the signed 32-bit difference.
    const auto ahead = static_cast<std::int32_t>(sequence - m_sequence);
    if (ahead == 0) {
      ++counters.duplicated;
      return Verdict::duplicate;
    }
    if (ahead < 0 || timestamp_ns < m_timestamp_ns) {
      ++counters.stale;
      return Verdict::stale;
    }
    counters.lost += static_cast<std::uint64_t>(ahead - 1);
  }
  m_any = true;
  m_sequence = sequence;
  m_timestamp_ns = timestamp_ns;
  ++counters.accepted;
  return Verdict::accept;
}

namespace {

/// Decode, count and filter one datagram of either direction (the two receive functions below).
template <class Packet>
bool receive(std::span<const std::byte> datagram, SequenceFilter& filter, LinkCounters& counters, Packet& out) noexcept {
  ++counters.received;
  Packet p;
  if (const DecodeError e = decode(datagram, p); e != DecodeError::none) {
    count_error(e, counters);
    return false;
  }
  if (filter.admit(p.sequence, p.timestamp_ns, counters) != SequenceFilter::Verdict::accept) return false;
  out = p;
  return true;
}

} // namespace

bool receive_device_state(std::span<const std::byte> datagram, SequenceFilter& filter, LinkCounters& counters,
                          DeviceStatePacket& out) noexcept {
  return receive(datagram, filter, counters, out);
}

bool receive_force_command(std::span<const std::byte> datagram, SequenceFilter& filter, LinkCounters& counters,
                           ForceCommandPacket& out) noexcept {
  return receive(datagram, filter, counters, out);
}

} // namespace kerf
