#include "realtime/haptics/udp_device.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <netdb.h>
#include <netinet/in.h>
#include <stdexcept>
#include <sys/socket.h>
#include <unistd.h>

namespace kerf {

std::uint64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<std::uint64_t>(ts.tv_nsec);
}

UdpDevice::UdpDevice(const std::string& host, int port) : m_address("udp://" + host + ":" + std::to_string(port)) {
  if (port <= 0 || port > 65535) throw std::invalid_argument(m_address + ": port must be in 1..65535");
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (const int e = getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); e != 0)
    throw std::invalid_argument(m_address + ": cannot resolve host: " + gai_strerror(e));
  m_socket = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (m_socket < 0) {
    freeaddrinfo(found);
    throw std::invalid_argument(m_address + ": socket: " + std::strerror(errno));
  }
  const int rc = connect(m_socket, found->ai_addr, found->ai_addrlen);
  freeaddrinfo(found);
  if (rc != 0) {
    const int e = errno;
    close(m_socket);
    throw std::invalid_argument(m_address + ": connect: " + std::strerror(e));
  }
}

UdpDevice::~UdpDevice() {
  if (m_socket >= 0) close(m_socket);
}

bool UdpDevice::poll(double now) noexcept {
  bool fresh = false;
  for (;;) {
    const ssize_t n = recv(m_socket, m_buffer.data(), m_buffer.size(), MSG_TRUNC);
    if (n < 0) {
      // EAGAIN: nothing more; ECONNREFUSED: an ICMP "port unreachable" for an earlier command
      // (the device is not listening yet or any more) -- the watchdog handles the silence.
      if (errno == EINTR) continue;
      break;
    }
    // MSG_TRUNC returns the real length: an oversized datagram is rejected by its size.
    const std::size_t size = static_cast<std::size_t>(n);
    DeviceStatePacket p;
    const std::span<const std::byte> datagram(m_buffer.data(), std::min(size, m_buffer.size()));
    if (size > m_buffer.size()) {
      ++m_counters.received;
      ++m_counters.malformed;
      continue;
    }
    if (receive_device_state(datagram, m_filter, m_counters, p)) {
      m_state.position = p.position;
      m_state.orientation = p.orientation;
      m_state.buttons = p.buttons;
      m_state.max_force = p.max_force;
      m_state.sequence = p.sequence;
      m_state.received_time = now;
      m_has_state = true;
      fresh = true;
    }
  }
  return fresh;
}

void UdpDevice::command(const Eigen::Vector3d& force, const Eigen::Vector3d& torque, std::uint32_t status,
                        double /*now*/) noexcept {
  ForceCommandPacket p;
  p.sequence = ++m_sequence;
  p.timestamp_ns = monotonic_ns();
  p.echo_sequence = m_state.sequence;
  p.status = status;
  p.force = force;
  p.torque = torque;
  std::array<std::byte, force_command_packet_size> bytes;
  encode(p, bytes);
  if (send(m_socket, bytes.data(), bytes.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(bytes.size())) ++m_send_failures;
}

} // namespace kerf
