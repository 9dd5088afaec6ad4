#include "realtime/haptics/device_emulator.hpp"

#include "realtime/haptics/udp_device.hpp"

#include <arpa/inet.h>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <netinet/in.h>
#include <stdexcept>
#include <sys/socket.h>
#include <unistd.h>

namespace kerf {

DeviceEmulator::DeviceEmulator(const EmulatedDeviceSettings& settings) : m_settings(settings) {
  if (settings.target.empty()) throw std::invalid_argument("device emulator: the target trajectory is empty");
  if (!(settings.rate > 0.0) || !(settings.target_rate > 0.0))
    throw std::invalid_argument("device emulator: rates must be positive");
  if (!(settings.max_force >= 0.0) || !std::isfinite(settings.max_force))
    throw std::invalid_argument("device emulator: max_force must be finite and >= 0");
  const std::string where = settings.host + ":" + std::to_string(settings.port);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(settings.port));
  if (inet_pton(AF_INET, settings.host.c_str(), &address.sin_addr) != 1)
    throw std::runtime_error("device emulator: " + where + ": host must be a numeric IPv4 address");
  m_socket = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (m_socket < 0) throw std::runtime_error("device emulator: socket: " + std::string(std::strerror(errno)));
  if (bind(m_socket, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int e = errno;
    close(m_socket);
    throw std::runtime_error("device emulator: cannot bind " + where + ": " + std::strerror(e));
  }
  socklen_t length = sizeof address;
  getsockname(m_socket, reinterpret_cast<sockaddr*>(&address), &length);
  m_port = ntohs(address.sin_port);
  m_received.reserve(static_cast<std::size_t>(motion_duration() * settings.rate * 2.0) + 1024);
}

DeviceEmulator::~DeviceEmulator() {
  if (m_socket >= 0) close(m_socket);
}

double DeviceEmulator::motion_duration() const noexcept {
  return m_settings.hold + static_cast<double>(m_settings.target.size() - 1) / m_settings.target_rate +
         m_settings.tail;
}

void DeviceEmulator::run(const std::atomic<bool>& stop) {
  const auto& target = m_settings.target;
  const double dt = 1.0 / m_settings.rate;
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / m_settings.rate));
  SimulatedHand hand(m_settings.hand, target.front());
  SequenceFilter filter;
  sockaddr_in peer{};
  bool have_peer = false;
  double first_command = -1.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  double force_time = -1.0;
  std::uint32_t sequence = 0;
  std::array<std::byte, 512> buffer{};
  const std::int64_t start = static_cast<std::int64_t>(monotonic_ns());

  for (std::int64_t k = 1;; ++k) {
    const std::int64_t deadline = start + k * period_ns;
    timespec ts{static_cast<time_t>(deadline / 1000000000), static_cast<long>(deadline % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
    const double now = 1e-9 * static_cast<double>(static_cast<std::int64_t>(monotonic_ns()) - start);
    if (stop.load(std::memory_order_relaxed)) break;
    if (first_command >= 0.0 && now - first_command > motion_duration()) break;

    // Every pending command: the newest valid one is the force to display.
    for (;;) {
      sockaddr_in from{};
      socklen_t from_length = sizeof from;
      const ssize_t n = recvfrom(m_socket, buffer.data(), buffer.size(), MSG_TRUNC, reinterpret_cast<sockaddr*>(&from),
                                 &from_length);
      if (n < 0) {
        if (errno == EINTR) continue;
        break;
      }
      ForceCommandPacket command;
      const auto size = static_cast<std::size_t>(n);
      if (size > buffer.size()) {
        ++m_counters.received;
        ++m_counters.malformed;
        continue;
      }
      if (!receive_force_command({buffer.data(), size}, filter, m_counters, command)) continue;
      peer = from;
      have_peer = true;
      if (first_command < 0.0) first_command = now;
      force = command.force;
      force_time = now;
      m_received.push_back({now, command.sequence, command.status, command.force, hand.position()});
    }
    if (!have_peer) continue;

    // The target: held at the start for `hold`, then the trajectory, then held at its end.
    const double tau = std::max(0.0, now - first_command - m_settings.hold) * m_settings.target_rate;
    const auto j = std::min(static_cast<std::size_t>(tau), target.size() - 1);
    const std::size_t j1 = std::min(j + 1, target.size() - 1);
    const double s = j1 == j ? 0.0 : tau - static_cast<double>(j);
    const Eigen::Vector3d x_target = target[j] + s * (target[j1] - target[j]);
    const Eigen::Vector3d v_target =
        (j1 == j || now - first_command < m_settings.hold) ? Eigen::Vector3d::Zero()
                                                            : Eigen::Vector3d((target[j1] - target[j]) * m_settings.target_rate);
    // A device displays no force older than its own timeout.
    const Eigen::Vector3d applied =
        (force_time >= 0.0 && now - force_time <= m_settings.command_timeout) ? force : Eigen::Vector3d::Zero();
    hand.step(x_target, v_target, applied, dt);

    DeviceStatePacket state;
    state.sequence = ++sequence;
    state.timestamp_ns = monotonic_ns();
    state.position = hand.position();
    state.max_force = m_settings.max_force;
    if (m_settings.emergency_stop_at >= 0.0 && now - first_command >= m_settings.emergency_stop_at)
      state.buttons |= emergency_stop_button;
    std::array<std::byte, device_state_packet_size> bytes;
    encode(state, bytes);
    sendto(m_socket, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&peer), sizeof peer);
  }
  close(m_socket);
  m_socket = -1;
}

} // namespace kerf
