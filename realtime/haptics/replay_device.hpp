#pragma once
// `replay:FILE`: a device that plays a recorded or scripted trajectory instead of a hand. FILE is
// either a trajectory CSV (header `t,px,py,pz`, seconds and metres, strictly increasing t, the
// format of a scene's recorded trajectory) or a kerf session file (its first tool; `replay:FILE#N`
// picks tool N of a session; its times must increase strictly too). The position is linearly interpolated at the time since the first
// poll and held at the last sample afterwards. Commands are accepted and kept (last_force()).

#include "realtime/haptics/haptic_device.hpp"

#include <filesystem>
#include <vector>

namespace kerf {

class ReplayDevice final : public HapticDevice {
public:
  /// Reads the file (throws std::runtime_error naming file:line on a bad one). `max_force` [N]
  /// is the maximum this device declares (the rig's configured clamp applies as well).
  ReplayDevice(const std::filesystem::path& file, int tool, double max_force);

  [[nodiscard]] std::string_view address() const noexcept override { return m_address; }
  bool poll(double now) noexcept override;
  [[nodiscard]] bool has_state() const noexcept override { return m_has_state; }
  [[nodiscard]] const DeviceState& state() const noexcept override { return m_state; }
  void command(const Eigen::Vector3d& force, const Eigen::Vector3d& torque, std::uint32_t status,
               double now) noexcept override;
  [[nodiscard]] const LinkCounters& counters() const noexcept override { return m_counters; }

  [[nodiscard]] const Eigen::Vector3d& last_force() const noexcept { return m_force; }
  [[nodiscard]] double duration() const noexcept { return m_times.back() - m_times.front(); }

private:
  std::string m_address;
  std::vector<double> m_times;
  std::vector<Eigen::Vector3d> m_positions;
  DeviceState m_state;
  bool m_has_state = false;
  double m_start = 0.0;
  std::size_t m_cursor = 0;
  std::uint32_t m_sequence = 0;
  LinkCounters m_counters;
  Eigen::Vector3d m_force = Eigen::Vector3d::Zero();
};

} // namespace kerf
