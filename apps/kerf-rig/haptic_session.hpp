#pragma once
// One session at the rig: a scene's model driven by haptic devices in the servo loop
// (realtime/haptics/servo_loop.hpp), with the safety layer, the optional virtual coupling and
// recording, then the timing, link and safety report. `kerf-rig haptic` and `kerf-rig replay`
// run it; docs/haptic-rig.md.

#include "realtime/haptics/device_specs.hpp"
#include "realtime/haptics/safety_layer.hpp"
#include "realtime/haptics/servo_loop.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace kerf::cli {

/// What a session is run with: the command-line options of `kerf-rig haptic`.
struct HapticOptions {
  std::string scene;                ///< scene file or name
  std::string model;                ///< catalogue name
  std::vector<std::string> devices; ///< one address per tool, in scene order (udp_device.hpp, open_device)
  double rate = 1000.0;             ///< servo rate [Hz]
  double model_rate = 0.0;          ///< model thread rate [Hz]; 0: in the servo thread
  std::string record;               ///< session file to record to; empty: none
  double duration = 0.0;            ///< [s] until the ramp out; 0: until stopped
  std::string device_model{default_device_model};
  double max_force = default_safety_limits.max_force;
  double force_rate = default_safety_limits.max_force_rate;
  double ramp = default_safety_limits.ramp_time;
  double watchdog = default_safety_limits.watchdog_timeout;
  bool max_force_given = false; ///< --max-force on the command line (else the device model's)
  bool watchdog_given = false;  ///< --watchdog on the command line (else default_watchdog_timeout(rate))
  VirtualCoupling coupling;
  bool no_realtime = false;
};

/// The options every session command takes: rate, model rate, recording, duration, device model,
/// safety limits, virtual coupling, real-time scheduling.
void add_servo_options(CLI::App& command, HapticOptions& options);

/// After parsing: which of the defaults were overridden on the command line (--max-force,
/// --watchdog), for run_haptic's limits.
void read_given_servo_options(const CLI::App& command, HapticOptions& options);

/// The catalogue's model names, comma-separated, for the --model option's help.
std::string model_names();

/// Runs the session until its duration or an emergency stop (SIGINT, SIGTERM, a device's e-stop
/// button), and prints its report. Throws std::invalid_argument
/// on options the named device or the scene refuse (a clamp above the device's maximum force, a
/// device count other than the scene's tool count).
void run_haptic(const HapticOptions& options);

} // namespace kerf::cli
