#include "fuzz/fuzz_targets.hpp"

#include "realtime/haptics/device_protocol.hpp"

#include <array>
#include <cmath>
#include <cstring>

namespace kerf::fuzz {

void fuzz_device_protocol(std::span<const std::byte> data) {
  SequenceFilter filter;
  LinkCounters counters;
  std::uint64_t datagrams = 0;
  std::size_t at = 0;
  while (at < data.size()) {
    const std::size_t length = std::min<std::size_t>(std::to_integer<std::size_t>(data[at]), data.size() - at - 1);
    const std::span<const std::byte> datagram = data.subspan(at + 1, length);
    at += 1 + length;
    ++datagrams;

    DeviceStatePacket state;
    if (decode(datagram, state) == DecodeError::none) {
      // The decoder's promise (device_protocol.hpp): finite position and max_force >= 0, a
      // finite orientation within 1e-3 of unit norm; and the layout has no spare bits.
      if (!state.position.allFinite() || !std::isfinite(state.max_force) || state.max_force < 0.0 ||
          !state.orientation.allFinite() || std::abs(state.orientation.norm() - 1.0) > 1e-3)
        throw FuzzFinding("device state decoded with an invalid value");
      std::array<std::byte, device_state_packet_size> again{};
      encode(state, again);
      if (std::memcmp(again.data(), datagram.data(), again.size()) != 0)
        throw FuzzFinding("device state does not encode back to its bytes");
    }
    ForceCommandPacket command;
    if (decode(datagram, command) == DecodeError::none) {
      if (!command.force.allFinite() || !command.torque.allFinite())
        throw FuzzFinding("force command decoded with a non-finite force or torque");
      std::array<std::byte, force_command_packet_size> again{};
      encode(command, again);
      if (std::memcmp(again.data(), datagram.data(), again.size()) != 0)
        throw FuzzFinding("force command does not encode back to its bytes");
    }
    DeviceStatePacket newest;
    receive_device_state(datagram, filter, counters, newest);
  }
  // LinkCounters: every received datagram is either accepted or dropped for exactly one reason.
  if (counters.received != datagrams || counters.received != counters.accepted + counters.dropped())
    throw FuzzFinding("link counters do not add up");
}

} // namespace kerf::fuzz
