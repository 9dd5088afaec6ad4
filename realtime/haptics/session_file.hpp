#pragma once
// The session file of a haptic run (docs/haptic-rig.md, "Session file"): every servo tick, one
// CSV row per tool, after two comment lines and a header:
//   # kerf haptic session v1
//   # rate_hz=1000 model=fracture scene=potato_rect_cut tools=blade[;other]
//   tick,t,tool,px,py,pz,vx,vy,vz,qw,qx,qy,qz,buttons,model_fx,model_fy,model_fz,fx,fy,fz,mode,
//   crack_extent,compute_s,late_s,link_age_s,status,injected_j
// The file is append-only: rows are written in tick order and flushed in batches, so after a
// crash it is complete up to the last flushed tick; a reader drops a final line that has no
// newline (a row cut by the crash). t is the model time (tick x 1/rate): the model saw position
// p and velocity v at t and returned model_f; f is what the safety layer commanded.

#include "realtime/force_sample.hpp"
#include "realtime/tool_state.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// The most tools (devices) one session drives.
inline constexpr int max_session_tools = 2;

/// One tool's part of a tick.
struct ToolTick {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     ///< [m] as given to the model
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();     ///< [m/s] as given to the model
  Eigen::Vector4d orientation{1.0, 0.0, 0.0, 0.0};        ///< device quaternion (w, x, y, z)
  std::uint32_t buttons = 0;
  Eigen::Vector3d model_force = Eigen::Vector3d::Zero();  ///< the model's force [N] (before safety; NaN/Inf if the model returned one)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();        ///< the commanded force [N] (after safety)
  InteractionMode mode = InteractionMode::no_contact;
  double crack_extent = 0.0;  ///< [m]
  double link_age = 0.0;      ///< [s] since the device's last accepted state
  std::uint32_t status = 0;   ///< SafetyStatus bits
  double injected = 0.0;      ///< passivity observer: energy the rig has injected so far [J]
};

/// One servo tick (plain data, copied into the recorder's ring without allocation).
struct TickRecord {
  std::uint64_t tick = 0;  ///< index of the model step (0 = first step with every device present)
  double t = 0.0;          ///< model time [s]
  double compute = 0.0;    ///< model step wall time [s]
  double late = 0.0;       ///< wake-up lateness of this tick [s]
  int tools = 0;
  std::array<ToolTick, max_session_tools> tool{};
};

/// What the header lines say.
struct SessionHeader {
  double rate = 0.0;                 ///< servo rate [Hz]
  std::string model;
  std::string scene;
  std::vector<std::string> tools;    ///< tool names in device order
};

/// A session read back.
struct Session {
  SessionHeader header;
  std::vector<TickRecord> ticks;
};

/// The CSV column header, exactly.
inline constexpr const char* session_csv_header =
    "tick,t,tool,px,py,pz,vx,vy,vz,qw,qx,qy,qz,buttons,model_fx,model_fy,model_fz,fx,fy,fz,mode,"
    "crack_extent,compute_s,late_s,link_age_s,status,injected_j";

/// Reads a session file. Throws std::runtime_error naming file:line on a wrong header, a wrong
/// column count, a bad number, an unknown tool or mode, or ticks out of order. A last line
/// without a newline is ignored (see above), as is a last tick missing some of its tools.
Session read_session(const std::filesystem::path& file);

/// The tool states of each tool (in header order) over the session: what the model was given.
std::vector<std::vector<ToolState>> session_tool_states(const Session& session);

} // namespace kerf
