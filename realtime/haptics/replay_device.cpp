#include "realtime/haptics/replay_device.hpp"

#include "realtime/haptics/session_file.hpp"
#include "realtime/haptics/udp_device.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace kerf {

namespace {

/// Reads `t,px,py,pz` rows (comments with '#').
void read_trajectory_csv(const std::filesystem::path& file, std::vector<double>& times,
                         std::vector<Eigen::Vector3d>& points) {
  std::ifstream in(file);
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line != "t,px,py,pz")
        throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": expected the header \"t,px,py,pz\"");
      header = true;
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    if (fields.size() != 4)
      throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": expected 4 columns (t,px,py,pz)");
    double v[4];
    for (std::size_t n = 0; n < 4; ++n) {
      char* end = nullptr;
      v[n] = std::strtod(fields[n].c_str(), &end);
      // The whole field: a NUL byte inside it ends strtod's string, not the field.
      if (fields[n].empty() || end != fields[n].c_str() + fields[n].size() || !std::isfinite(v[n]))
        throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": column " + std::to_string(n + 1) +
                                 ": expected a finite number, found \"" + fields[n] + "\"");
    }
    if (!times.empty() && !(v[0] > times.back()))
      throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": time must increase strictly");
    times.push_back(v[0]);
    points.emplace_back(v[1], v[2], v[3]);
  }
}

} // namespace

ReplayDevice::ReplayDevice(const std::filesystem::path& file, int tool, double max_force)
    : m_address("replay:" + file.string()) {
  std::ifstream probe(file);
  if (!probe) throw std::runtime_error(file.string() + ": cannot open the replay file");
  std::string first;
  std::getline(probe, first);
  probe.close();
  if (first == "# kerf haptic session v1") {
    const Session session = read_session(file);
    if (tool < 0 || static_cast<std::size_t>(tool) >= session.header.tools.size())
      throw std::runtime_error(file.string() + ": the session has no tool " + std::to_string(tool));
    for (const TickRecord& r : session.ticks) {
      // Interpolation divides by the time between samples: it must be positive (a trajectory
      // CSV is checked as it is read; a session file only orders its ticks).
      if (!m_times.empty() && !(r.t > m_times.back()))
        throw std::runtime_error(file.string() + ": tick " + std::to_string(r.tick) +
                                 ": time must increase strictly for a replay");
      m_times.push_back(r.t);
      m_positions.push_back(r.tool[static_cast<std::size_t>(tool)].position);
    }
  } else {
    if (tool != 0) throw std::runtime_error(file.string() + ": a trajectory CSV has one tool (0)");
    read_trajectory_csv(file, m_times, m_positions);
  }
  if (m_times.size() < 2) throw std::runtime_error(file.string() + ": a replay needs at least two samples");
  if (!(max_force > 0.0)) throw std::invalid_argument(m_address + ": max_force must be positive");
  m_state.max_force = max_force;
}

bool ReplayDevice::poll(double now) noexcept {
  if (!m_has_state) m_start = now;
  const double t = m_times.front() + (now - m_start);
  while (m_cursor + 2 < m_times.size() && t > m_times[m_cursor + 1]) ++m_cursor;
  // Linear interpolation between the bracketing samples, held at the ends.
  const double s =
      std::clamp((t - m_times[m_cursor]) / (m_times[m_cursor + 1] - m_times[m_cursor]), 0.0, 1.0);
  // (1 - s) p_k + s p_k+1: finite for finite samples, where p_k + s (p_k+1 - p_k) overflows when
  // the difference does (samples near ±1.8e308 m); within an ulp of overflow, the nearer sample.
  const Eigen::Vector3d& a = m_positions[m_cursor];
  const Eigen::Vector3d& b = m_positions[m_cursor + 1];
  m_state.position = (1.0 - s) * a + s * b;
  if (!m_state.position.allFinite()) m_state.position = s < 0.5 ? a : b;
  m_state.sequence = ++m_sequence;
  m_state.received_time = now;
  m_has_state = true;
  ++m_counters.received;
  ++m_counters.accepted;
  return true;
}

void ReplayDevice::command(const Eigen::Vector3d& force, const Eigen::Vector3d& /*torque*/, std::uint32_t /*status*/,
                           double /*now*/) noexcept {
  m_force = force;
}

std::unique_ptr<HapticDevice> open_device(const std::string& address) {
  if (address.rfind("udp://", 0) == 0) {
    const std::string rest = address.substr(6);
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == rest.size())
      throw std::invalid_argument("device \"" + address + "\": expected udp://HOST:PORT");
    char* end = nullptr;
    const long port = std::strtol(rest.c_str() + colon + 1, &end, 10);
    if (*end != '\0' || port <= 0 || port > 65535)
      throw std::invalid_argument("device \"" + address + "\": the port must be a number in 1..65535");
    return std::make_unique<UdpDevice>(rest.substr(0, colon), static_cast<int>(port));
  }
  if (address.rfind("replay:", 0) == 0) {
    std::string file = address.substr(7);
    int tool = 0;
    if (const auto hash = file.rfind('#'); hash != std::string::npos) {
      char* end = nullptr;
      tool = static_cast<int>(std::strtol(file.c_str() + hash + 1, &end, 10));
      if (*end != '\0' || hash + 1 == file.size())
        throw std::invalid_argument("device \"" + address + "\": expected replay:FILE or replay:FILE#TOOL");
      file.resize(hash);
    }
    if (file.empty()) throw std::invalid_argument("device \"" + address + "\": expected replay:FILE");
    // A replay has no actuator: it declares no limit of its own, so the rig's clamp governs.
    return std::make_unique<ReplayDevice>(file, tool, std::numeric_limits<double>::max());
  }
  throw std::invalid_argument("device \"" + address + "\": expected udp://HOST:PORT or replay:FILE");
}

} // namespace kerf
