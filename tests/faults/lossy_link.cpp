#include "tests/faults/lossy_link.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <deque>
#include <random>
#include <stdexcept>

namespace kerf::test {

namespace {

sockaddr_in loopback(int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
  return a;
}

int bound_socket(int& port) {
  const int s = socket(AF_INET, SOCK_DGRAM, 0);
  if (s < 0) throw std::runtime_error("lossy link: socket() failed");
  sockaddr_in a = loopback(0);
  if (bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) throw std::runtime_error("lossy link: bind() failed");
  socklen_t length = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &length);
  port = ntohs(a.sin_port);
  return s;
}

using Datagram = std::vector<std::byte>;

} // namespace

LossyLink::LossyLink(int device_port, const LinkFaults& faults) : m_faults(faults), m_device_port(device_port) {
  m_rig_socket = bound_socket(m_port);
  int unused = 0;
  m_device_socket = bound_socket(unused);
  m_thread = std::thread([this] { run(); });
}

LossyLink::~LossyLink() { stop(); }

void LossyLink::stop() {
  m_stop = true;
  if (m_thread.joinable()) m_thread.join();
  if (m_rig_socket >= 0) close(m_rig_socket);
  if (m_device_socket >= 0) close(m_device_socket);
  m_rig_socket = m_device_socket = -1;
}

void LossyLink::run() {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(clock::now() - start).count(); };
  std::mt19937 random(m_faults.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::uniform_int_distribution<std::size_t> cut(0, device_state_packet_size - 1);

  const sockaddr_in device = loopback(m_device_port);
  sockaddr_in rig{};
  bool have_rig = false;
  double first_state = -1.0;
  bool any_passed = false;
  double next_release = -1.0;
  std::deque<Datagram> held;     // stalled datagrams, released together
  Datagram reordered;            // one datagram waiting to follow the next
  std::array<std::byte, 512> buffer{};

  auto to_rig = [&](const Datagram& d) {
    if (!have_rig) return;
    sendto(m_rig_socket, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&rig), sizeof rig);
    ++m_log.delivered;
  };

  while (!m_stop.load(std::memory_order_relaxed)) {
    pollfd fds[2] = {{m_rig_socket, POLLIN, 0}, {m_device_socket, POLLIN, 0}};
    poll(fds, 2, 1);
    const double now = seconds();

    // Rig -> device: force commands, forwarded untouched and logged.
    for (;;) {
      sockaddr_in from{};
      socklen_t length = sizeof from;
      const ssize_t n = recvfrom(m_rig_socket, buffer.data(), buffer.size(), MSG_DONTWAIT,
                                 reinterpret_cast<sockaddr*>(&from), &length);
      if (n < 0) break;
      rig = from;
      have_rig = true;
      sendto(m_device_socket, buffer.data(), static_cast<std::size_t>(n), 0, reinterpret_cast<const sockaddr*>(&device),
             sizeof device);
      ForceCommandPacket command;
      if (decode({buffer.data(), static_cast<std::size_t>(n)}, command) == DecodeError::none)
        m_log.commands.push_back({now, command.force, command.status, command.sequence, command.timestamp_ns,
                                  command.echo_sequence});
    }

    // Device -> rig: states, damaged as configured.
    for (;;) {
      const ssize_t n = recv(m_device_socket, buffer.data(), buffer.size(), MSG_DONTWAIT);
      if (n < 0) break;
      ++m_log.states;
      Datagram d(buffer.begin(), buffer.begin() + n);
      DeviceStatePacket state;
      const bool whole = decode(d, state) == DecodeError::none;
      const std::uint32_t sequence = whole ? state.sequence : 0;
      if (first_state < 0.0) first_state = now;
      const std::uint64_t sent_at = state.timestamp_ns;
      if (whole && m_faults.clock_jump_after >= 0.0 && now - first_state >= m_faults.clock_jump_after) {
        // The device's clock has jumped: the same state, stamped clock_jump_ns later (or earlier).
        if (m_log.first_jumped == 0) m_log.first_jumped = sequence;
        state.timestamp_ns = static_cast<std::uint64_t>(static_cast<std::int64_t>(state.timestamp_ns) + m_faults.clock_jump_ns);
        encode(state, std::span<std::byte, device_state_packet_size>(d.data(), device_state_packet_size));
      }
      if (m_faults.silent_after >= 0.0 && now - first_state >= m_faults.silent_after) {
        if (m_log.silenced_at < 0.0) m_log.silenced_at = now;
        continue;
      }
      if (uniform(random) < m_faults.drop) {
        m_log.dropped.push_back(sequence);
        continue;
      }
      if (uniform(random) < m_faults.truncate) {
        d.resize(cut(random));
        ++m_log.truncated;
      }
      if (!any_passed) {
        m_log.first_delivered = sequence;
        any_passed = true;
      }
      if (d.size() == device_state_packet_size && whole) m_log.delivered_states.push_back({sequence, sent_at});
      if (m_faults.stall_period > 0.0) {
        held.push_back(std::move(d));
        continue;
      }
      if (reordered.empty() && uniform(random) < m_faults.reorder) {
        reordered = std::move(d);
        ++m_log.reordered;
        continue;
      }
      to_rig(d);
      if (uniform(random) < m_faults.duplicate) {
        to_rig(d);
        ++m_log.duplicated;
      }
      if (!reordered.empty()) {
        to_rig(reordered);
        reordered.clear();
      }
    }

    // A stalled link delivers everything it held at once, once per period.
    if (m_faults.stall_period > 0.0 && first_state >= 0.0) {
      if (next_release < 0.0) next_release = first_state + m_faults.stall_period;
      if (now >= next_release) {
        for (const Datagram& d : held) to_rig(d);
        if (!held.empty()) ++m_log.stalls;
        held.clear();
        next_release += m_faults.stall_period;
      }
    }
  }
}

} // namespace kerf::test
