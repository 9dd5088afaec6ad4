#pragma once
// The haptic servo loop (docs/haptic-rig.md): a thread at a fixed rate that sleeps to absolute
// deadlines (clock_nanosleep, TIMER_ABSTIME, CLOCK_MONOTONIC), reads every device, steps the model
// (or, when the model runs slower than the device, renders the model thread's force by linear
// interpolation), passes each force through that device's SafetyLayer, commands the devices,
// observes the energy injected (passivity observer) and records the tick. Everything the tick
// touches is allocated before the first tick.
//
// Device i drives tool i of the model: the model's tool_count() must equal the device count.

#include "realtime/haptics/haptic_device.hpp"
#include "realtime/haptics/realtime_scheduling.hpp"
#include "realtime/haptics/safety_layer.hpp"
#include "realtime/haptics/session_recorder.hpp"
#include "realtime/haptics/timing_statistics.hpp"
#include "realtime/haptics/triple_buffer.hpp"
#include "realtime/tool_model.hpp"

#include <atomic>
#include <functional>
#include <span>
#include <vector>

namespace kerf {

/// Colgate's virtual coupling (Colgate, Stanley & Brown, IROS 1995; Adams & Hannaford, IEEE
/// TRA 1999): the model's tool is a virtual tool of mass m_v joined to the device by a spring
/// k_c and damper b_c, so the device never renders a stiffness above k_c whatever the model
/// does. Per tick (T), with the model force F_m on the virtual tool at x_v and the device at
/// (x_d, v_d), the virtual tool moves semi-implicitly in the coupling:
///   m_v (v+ - v) / T = F_m - k_c (x_v+ - x_d) - b_c (v+ - v_d),  x_v+ = x_v + T v+,
/// and the device is commanded the coupling force F_d = k_c (x_v+ - x_d) + b_c (v+ - v_d).
/// The model force enters explicitly: stable for model stiffness k_m up to ~4 m_v / T^2.
struct VirtualCoupling {
  double stiffness = 0.0;     ///< k_c [N/m]; 0 = no coupling (the model's force is rendered directly)
  double damping = 0.0;       ///< b_c [N s/m] >= 0
  double virtual_mass = 0.0;  ///< m_v [kg] > 0 when the coupling is on
};

/// Settings of one session.
struct ServoSettings {
  double rate = 1000.0;       ///< servo (device) rate [Hz], 100 to 10000
  double model_rate = 0.0;    ///< 0: the model steps in the servo thread; else its own thread at this rate [Hz] < rate
  double duration = 0.0;      ///< [s] from the start of the loop until the ramp out begins; 0: until stopped
  SafetyLimits safety;        ///< applied to every device
  VirtualCoupling coupling;   ///< off unless coupling.stiffness > 0
  bool realtime = true;       ///< try SCHED_FIFO and mlockall (falls back with a warning)
  int priority = 80;          ///< SCHED_FIFO priority of the servo thread (the model thread gets one less)
  /// The CPU the servo thread is pinned to (with `realtime`); -1: wherever the scheduler puts it.
  /// run_live_view pins it when the view renders beside it (viewer/live_session.hpp).
  int cpu = -1;
  /// Called once from the servo thread, before its first tick, with what real-time setup it got
  /// (so a command line can warn at the start of a session). May be empty.
  std::function<void(const RealtimeSetup&)> on_realtime;
};

/// What a session did.
struct ServoReport {
  RealtimeSetup realtime;
  TimingStatistics timing;                 ///< of the servo thread
  TimingStatistics model_timing;           ///< of the model thread (multi-rate only)
  std::vector<LinkCounters> links;         ///< per device
  std::vector<SafetyCounters> safety;      ///< per device
  std::vector<double> injected_energy;     ///< per device: passivity observer [J]
  std::uint64_t model_steps = 0;
  /// Model steps that reported themselves over budget (ForceSample::over_budget on any tool: a
  /// solver that did not converge in its bounded work, a voxel neighbourhood over capacity, …).
  std::uint64_t model_steps_over_budget = 0;
  /// Model steps whose compute time exceeded their period (1 / the model's rate).
  std::uint64_t model_steps_over_period = 0;
  std::uint64_t records_dropped = 0;       ///< ticks the recorder's ring could not take
  bool emergency_stopped = false;
};

class ServoLoop {
public:
  /// Checks the settings and the tool/device count (std::invalid_argument naming what is
  /// wrong) and allocates everything the ticks use. `recorder` may be null.
  ServoLoop(ToolModel& model, std::span<HapticDevice* const> devices, const ServoSettings& settings,
            SessionRecorder* recorder);
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  /// Runs the session on its own thread(s) and returns when it has ended: after the duration
  /// and the ramp out, after request_stop() and the ramp out, or at once after an emergency stop.
  ServoReport run();

  /// Ends the session with a ramp out. Async-signal-safe (one atomic store).
  void request_stop() noexcept { m_stop_requested.store(true, std::memory_order_relaxed); }
  /// Zeroes every force at the next tick and ends the session. Async-signal-safe.
  void request_emergency_stop() noexcept { m_emergency_requested.store(true, std::memory_order_relaxed); }

  /// One servo tick at rig time `now` [s]: its deadline, since the loop started (run() passes
  /// k T for tick k, plus the periods of any skipped deadlines), woken `late` [s] after it. Allocation-free. Returns false once the session has ended. (run() calls this;
  /// tests may call it directly, in single-rate mode.)
  bool tick(double now, double late) noexcept;

  [[nodiscard]] const TimingStatistics& timing() const noexcept { return m_timing; }
  [[nodiscard]] const SafetyLayer& safety(std::size_t device) const { return m_safety.at(device); }
  [[nodiscard]] double injected_energy(std::size_t device) const { return m_injected.at(device); }
  [[nodiscard]] std::uint64_t model_steps() const noexcept { return m_model_steps; }
  /// Model steps so far that reported themselves over budget / took longer than their period.
  [[nodiscard]] std::uint64_t model_steps_over_budget() const noexcept { return m_model_over_budget; }
  [[nodiscard]] std::uint64_t model_steps_over_period() const noexcept { return m_model_over_period; }

private:
  /// What the model thread publishes (multi-rate).
  struct ModelOutput {
    double time = -1.0;   ///< rig time of the positions it stepped at [s]
    double compute = 0.0; ///< [s]
    std::array<ForceSample, max_session_tools> forces{};
  };
  /// What the servo publishes to the model thread (multi-rate).
  struct ModelInput {
    double time = -1.0;
    std::array<ToolState, max_session_tools> tools{};
  };

  void servo_thread();
  void model_thread();
  void step_model(std::span<const ToolState> tools, double dt, std::span<ForceSample> out, double& compute) noexcept;
  /// The steps of `tick`: 1. poll the devices and switch to emergency stop, active or stopping;
  /// 2. the model's tool states at tick k (a coupled model's: the virtual tools); 3. the
  /// multi-rate model's output, first-order held (returns its compute time), and the force to
  /// render (direct or through the virtual coupling); 4. safety, command, passivity observer
  /// and the tick's record (returns whether every device has stopped with zero force).
  void read_devices(double now) noexcept;
  void read_tool_states(std::uint64_t k) noexcept;
  double hold_model_output(double now) noexcept;
  void render_forces() noexcept;
  bool command_devices(double now, bool first) noexcept;

  ToolModel& m_model;
  std::vector<HapticDevice*> m_devices;
  ServoSettings m_settings;
  SessionRecorder* m_recorder;
  std::size_t m_count;
  double m_period;

  std::vector<SafetyLayer> m_safety;
  std::vector<ToolState> m_tools;
  std::vector<ForceSample> m_forces;
  std::vector<Eigen::Vector3d> m_previous_position;
  std::vector<Eigen::Vector3d> m_previous_force;
  std::vector<double> m_injected;
  std::vector<Eigen::Vector3d> m_virtual_position; ///< coupling: virtual tool x_v [m]
  std::vector<Eigen::Vector3d> m_virtual_velocity; ///< coupling: virtual tool v_v [m/s]
  std::vector<ToolState> m_device_tools;          ///< coupling: the devices' own states
  std::vector<Eigen::Vector3d> m_desired;         ///< force handed to the safety layer [N]
  TimingStatistics m_timing;
  TimingStatistics m_model_timing;
  TickRecord m_record;

  bool m_active = false;
  bool m_stopping = false;
  bool m_emergency = false;
  int m_final_ticks = 0;
  double m_last_now = 0.0;
  bool m_finished = false;
  std::uint64_t m_model_steps = 0;
  std::uint64_t m_model_over_budget = 0; ///< written by the thread that steps the model, read after it
  std::uint64_t m_model_over_period = 0;
  std::atomic<bool> m_stop_requested{false};
  std::atomic<bool> m_emergency_requested{false};
  std::atomic<bool> m_model_thread_done{false};

  // Multi-rate: the latest positions for the model thread, and its last two outputs for
  // interpolation (previous and newest).
  TripleBuffer<ModelInput> m_to_model;
  TripleBuffer<ModelOutput> m_from_model;
  ModelOutput m_model_previous;
  ModelOutput m_model_newest;
  RealtimeSetup m_realtime;
};

} // namespace kerf
