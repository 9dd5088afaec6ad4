#include "realtime/haptics/servo_loop.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <ctime>
#include <stdexcept>
#include <string>
#include <thread>

namespace kerf {

namespace {

/// Zero-force ticks sent after the session has ended (the device sees zero even if one is lost).
constexpr int final_zero_ticks = 10;

std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t deadline) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / 1000000000);
  ts.tv_nsec = static_cast<long>(deadline % 1000000000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

/// Sleeps to absolute deadlines start + k T and keeps `stats`. `work(now_s, late_s)` is called
/// with the deadline's time since the start (the loop's own clock: whole periods, so an interval
/// of n ticks is n T whatever the wake-up jitter) and how late it woke; it returns false to end
/// the loop; `stop` ends it too. A tick whose work ends after the next deadline is
/// an overrun; the deadlines it covered are skipped (counted as missed), not caught up.
template <typename Work>
void run_periodic(double rate, TimingStatistics& stats, const std::atomic<bool>* stop, Work&& work) noexcept {
  const auto period = static_cast<std::int64_t>(std::llround(1e9 / rate));
  const std::int64_t start = now_ns();
  std::int64_t k = 1;
  std::int64_t previous_wake = start;
  for (;;) {
    const std::int64_t deadline = start + k * period;
    sleep_until_ns(deadline);
    const std::int64_t wake = now_ns();
    stats.lateness.add(1e-9 * static_cast<double>(wake - deadline));
    if (stats.ticks > 0) stats.period_jitter.add(1e-9 * std::abs(static_cast<double>(wake - previous_wake - period)));
    previous_wake = wake;
    const bool go = work(1e-9 * static_cast<double>(deadline - start), 1e-9 * static_cast<double>(wake - deadline));
    const std::int64_t end = now_ns();
    stats.tick.add(1e-9 * static_cast<double>(end - wake));
    ++stats.ticks;
    ++k;
    if (end > start + k * period) { // the work ran past the next deadline
      ++stats.overruns;
      const std::int64_t next = (end - start) / period + 1;
      stats.missed_deadlines += static_cast<std::uint64_t>(next - k);
      k = next;
    }
    if (!go || (stop && stop->load(std::memory_order_relaxed))) break;
  }
}

} // namespace

ServoLoop::ServoLoop(ToolModel& model, std::span<HapticDevice* const> devices, const ServoSettings& settings,
                     SessionRecorder* recorder)
    : m_model(model), m_devices(devices.begin(), devices.end()), m_settings(settings), m_recorder(recorder),
      m_count(devices.size()), m_period(0.0) {
  if (!(settings.rate >= 100.0 && settings.rate <= 10000.0))
    throw std::invalid_argument("servo loop: rate must be in 100..10000 Hz (got " + std::to_string(settings.rate) + ")");
  if (settings.model_rate != 0.0 && !(settings.model_rate >= 1.0 && settings.model_rate < settings.rate))
    throw std::invalid_argument("servo loop: model rate must be 0 (in the servo thread) or in [1, rate) Hz (got " +
                                std::to_string(settings.model_rate) + ")");
  if (!(settings.duration >= 0.0) || !std::isfinite(settings.duration))
    throw std::invalid_argument("servo loop: duration must be >= 0 s");
  if (settings.cpu < -1)
    throw std::invalid_argument("servo loop: cpu must be -1 (not pinned) or a CPU number (got " + std::to_string(settings.cpu) + ")");
  if (m_devices.empty() || m_count > static_cast<std::size_t>(max_session_tools))
    throw std::invalid_argument("servo loop: 1 to " + std::to_string(max_session_tools) + " devices, got " +
                                std::to_string(m_count));
  for (const HapticDevice* d : m_devices)
    if (!d) throw std::invalid_argument("servo loop: a device is null");
  if (static_cast<std::size_t>(model.tool_count()) != m_count)
    throw std::invalid_argument("servo loop: model " + std::string(model.name()) + " takes " +
                                std::to_string(model.tool_count()) + " tool(s) but " + std::to_string(m_count) +
                                " device(s) were given (device i drives tool i)");
  const VirtualCoupling& c = settings.coupling;
  if (!(c.stiffness >= 0.0) || !std::isfinite(c.stiffness) ||
      (c.stiffness > 0.0 && (!(c.damping >= 0.0) || !std::isfinite(c.damping) || !(c.virtual_mass > 0.0) ||
                             !std::isfinite(c.virtual_mass))))
    throw std::invalid_argument("servo loop: virtual coupling needs stiffness >= 0, and when > 0 damping >= 0 and a "
                                "positive virtual mass");
  // A watchdog shorter than two periods zeroes the force whenever one state arrives a tick late.
  if (!(settings.safety.watchdog_timeout >= 2.0 / settings.rate))
    throw std::invalid_argument("servo loop: watchdog time must be at least two servo periods (" +
                                std::to_string(2.0 / settings.rate) + " s at " + std::to_string(settings.rate) +
                                " Hz; got " + std::to_string(settings.safety.watchdog_timeout) + " s)");
  m_period = 1.0 / settings.rate;
  for (std::size_t i = 0; i < m_count; ++i) m_safety.emplace_back(settings.safety);
  m_tools.resize(m_count);
  m_forces.resize(m_count);
  m_previous_position.assign(m_count, Eigen::Vector3d::Zero());
  m_previous_force.assign(m_count, Eigen::Vector3d::Zero());
  m_injected.assign(m_count, 0.0);
  m_virtual_position.assign(m_count, Eigen::Vector3d::Zero());
  m_virtual_velocity.assign(m_count, Eigen::Vector3d::Zero());
  m_device_tools.resize(m_count);
  m_desired.assign(m_count, Eigen::Vector3d::Zero());
  m_record.tools = static_cast<int>(m_count);
  m_model.reset();
}

void ServoLoop::step_model(std::span<const ToolState> tools, double dt, std::span<ForceSample> out,
                           double& compute) noexcept {
  const std::int64_t begin = now_ns();
  m_model.step(tools, dt, out);
  compute = 1e-9 * static_cast<double>(now_ns() - begin);
  // The session report's counts: steps the model flagged, steps longer than their period.
  bool flagged = false;
  for (const ForceSample& f : out) flagged = flagged || f.over_budget;
  m_model_over_budget += flagged ? 1 : 0;
  m_model_over_period += compute > dt ? 1 : 0;
}

void ServoLoop::read_devices(double now) noexcept {
  bool all_present = true;
  bool button_stop = false;
  for (HapticDevice* d : m_devices) {
    d->poll(now);
    all_present = all_present && d->has_state();
    button_stop = button_stop || (d->has_state() && (d->state().buttons & emergency_stop_button));
  }
  if (!m_emergency && (button_stop || m_emergency_requested.load(std::memory_order_relaxed))) {
    m_emergency = true;
    for (SafetyLayer& s : m_safety) s.emergency_stop();
  }
  if (!m_active && all_present && !m_stopping && !m_emergency) {
    m_active = true;
    for (SafetyLayer& s : m_safety) s.start(now);
  }
  if (!m_stopping &&
      (m_stop_requested.load(std::memory_order_relaxed) || (m_settings.duration > 0.0 && now >= m_settings.duration))) {
    m_stopping = true;
    for (SafetyLayer& s : m_safety) s.stop(now);
  }
}

void ServoLoop::read_tool_states(std::uint64_t k) noexcept {
  // Device positions; velocity by the backward difference (x_k - x_{k-1}) / T.
  const bool first = k == 0;
  for (std::size_t i = 0; i < m_count; ++i) {
    const Eigen::Vector3d& x = m_devices[i]->state().position;
    m_tools[i].velocity = first ? Eigen::Vector3d::Zero() : Eigen::Vector3d((x - m_previous_position[i]) / m_period);
    m_tools[i].position = x;
    m_tools[i].time = static_cast<double>(k) * m_period;
  }
  if (m_settings.coupling.stiffness > 0.0) { // the model is given the virtual tool, which starts where the device is
    for (std::size_t i = 0; i < m_count; ++i) {
      m_device_tools[i] = m_tools[i];
      if (first) {
        m_virtual_position[i] = m_tools[i].position;
        m_virtual_velocity[i].setZero();
      }
      m_tools[i].position = m_virtual_position[i];
      m_tools[i].velocity = m_virtual_velocity[i];
    }
  }
}

double ServoLoop::hold_model_output(double now) noexcept {
  ModelInput& in = m_to_model.write_slot();
  in.time = now;
  for (std::size_t i = 0; i < m_count; ++i) in.tools[i] = m_tools[i];
  m_to_model.publish();
  if (m_from_model.update()) {
    m_model_previous = m_model_newest;
    m_model_newest = m_from_model.read_slot();
  }
  // First-order hold, one model period behind: F(t) = F_prev + s (F_new - F_prev),
  // s = (t - t_new) / (t_new - t_prev) in [0, 1]: the force reaches each model output one model
  // period after it was computed, and never extrapolates.
  const ModelOutput& a = m_model_previous;
  const ModelOutput& b = m_model_newest;
  const double s = (b.time < 0.0 || a.time < 0.0 || b.time <= a.time)
                       ? 1.0
                       : std::clamp((now - b.time) / (b.time - a.time), 0.0, 1.0);
  for (std::size_t i = 0; i < m_count; ++i) {
    const Eigen::Vector3d fa = a.time < 0.0 ? b.forces[i].force : a.forces[i].force;
    m_forces[i] = b.forces[i];
    m_forces[i].force = b.time < 0.0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(fa + s * (b.forces[i].force - fa));
  }
  return b.compute;
}

void ServoLoop::render_forces() noexcept {
  // Rendering: the model's force directly, or through the virtual coupling (VirtualCoupling).
  const bool coupled = m_settings.coupling.stiffness > 0.0;
  for (std::size_t i = 0; i < m_count; ++i) {
    if (!coupled) {
      m_desired[i] = m_forces[i].force;
      continue;
    }
    const VirtualCoupling& c = m_settings.coupling;
    const Eigen::Vector3d& x_d = m_device_tools[i].position;
    const Eigen::Vector3d& v_d = m_device_tools[i].velocity;
    Eigen::Vector3d& x_v = m_virtual_position[i];
    Eigen::Vector3d& v_v = m_virtual_velocity[i];
    // A non-finite model force must not poison the virtual tool: it then feels the coupling only
    // (and the safety layer still sees the model's NaN through the coupling force below).
    const Eigen::Vector3d f_m = m_forces[i].force.allFinite() ? m_forces[i].force : Eigen::Vector3d::Zero();
    // v+ (m_v/T + b_c + k_c T) = m_v v / T + F_m - k_c (x_v - x_d) + b_c v_d
    const double T = m_period;
    v_v = (c.virtual_mass / T * v_v + f_m - c.stiffness * (x_v - x_d) + c.damping * v_d) /
          (c.virtual_mass / T + c.damping + c.stiffness * T);
    x_v += T * v_v;
    // F_d = k_c (x_v+ - x_d) + b_c (v+ - v_d)
    m_desired[i] = c.stiffness * (x_v - x_d) + c.damping * (v_v - v_d);
    if (!m_forces[i].force.allFinite()) m_desired[i] = m_forces[i].force;
  }
}

bool ServoLoop::command_devices(double now, bool first) noexcept {
  // The rate limit acts on the real time since the previous tick (longer after an overrun).
  const double elapsed = first ? m_period : std::max(now - m_last_now, 0.0);
  m_last_now = now;
  bool all_stopped = true;
  for (std::size_t i = 0; i < m_count; ++i) {
    HapticDevice& d = *m_devices[i];
    const DeviceState& state = d.state();
    const double link_age = now - state.received_time;
    std::uint32_t status = 0;
    const Eigen::Vector3d force =
        m_safety[i].filter(m_desired[i], now, link_age, elapsed, state.max_force, status);
    d.command(force, Eigen::Vector3d::Zero(), status, now);
    // Passivity observer (Hannaford & Ryu 2002, sampled): the force commanded at tick k-1 acts
    // while the device moves from x_{k-1} to x_k, so the energy the rig injects into the hand is
    // E_k = E_{k-1} + F_{k-1} . (x_k - x_{k-1}) [J]. E > 0 means the rig has supplied net energy.
    if (!first) m_injected[i] += m_previous_force[i].dot(state.position - m_previous_position[i]);
    m_previous_force[i] = force;
    m_previous_position[i] = state.position;
    all_stopped = all_stopped && m_safety[i].stopped(now) && force.isZero();

    ToolTick& r = m_record.tool[i];
    r.position = m_tools[i].position;
    r.velocity = m_tools[i].velocity;
    r.orientation = state.orientation;
    r.buttons = state.buttons;
    r.model_force = m_forces[i].force;
    r.force = force;
    r.mode = m_forces[i].mode;
    r.crack_extent = m_forces[i].crack_extent;
    r.link_age = link_age;
    r.status = status;
    r.injected = m_injected[i];
  }
  return all_stopped;
}

bool ServoLoop::tick(double now, double late) noexcept {
  if (m_finished) return false;
  // 1. Read every device.
  read_devices(now);
  if (!m_active) { // no state from every device yet: zero commands keep the link open
    const std::uint32_t status = safety_waiting | (m_emergency ? safety_emergency_stop : 0u);
    for (HapticDevice* d : m_devices) d->command(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), status, now);
    if ((m_stopping || m_emergency) && ++m_final_ticks >= final_zero_ticks) m_finished = true;
    return !m_finished;
  }

  // 2. Tool states.
  const std::uint64_t k = m_record.tick;
  const bool first = k == 0;
  read_tool_states(k);

  // 3. The model: stepped here, or its thread's output interpolated; the force to render.
  double compute = 0.0;
  if (m_settings.model_rate == 0.0) {
    step_model(m_tools, m_period, m_forces, compute);
    ++m_model_steps;
    m_timing.compute.add(compute);
  } else {
    compute = hold_model_output(now);
  }
  render_forces();

  // 4. Safety, command, passivity observer, record.
  m_record.t = static_cast<double>(k) * m_period;
  m_record.compute = compute;
  m_record.late = late;
  const bool all_stopped = command_devices(now, first);
  if (m_recorder) m_recorder->push(m_record);
  ++m_record.tick;
  if ((m_emergency || (m_stopping && all_stopped)) && ++m_final_ticks >= final_zero_ticks) m_finished = true;
  return !m_finished;
}

void ServoLoop::servo_thread() {
  if (m_settings.realtime) m_realtime = enter_realtime(m_settings.priority, m_settings.cpu);
  if (m_settings.on_realtime) m_settings.on_realtime(m_realtime);
  run_periodic(m_settings.rate, m_timing, nullptr, [this](double now, double late) { return tick(now, late); });
  m_model_thread_done.store(true, std::memory_order_relaxed);
}

void ServoLoop::model_thread() {
  if (m_settings.realtime) set_fifo_priority(std::max(1, m_settings.priority - 1));
  const double dt = 1.0 / m_settings.model_rate;
  std::array<ToolState, max_session_tools> tools{};
  std::array<ForceSample, max_session_tools> forces{};
  std::uint64_t steps = 0;
  run_periodic(m_settings.model_rate, m_model_timing, &m_model_thread_done, [&](double, double) {
    m_to_model.update();
    const ModelInput& in = m_to_model.read_slot();
    if (in.time < 0.0) return true; // no positions yet
    for (std::size_t i = 0; i < m_count; ++i) {
      tools[i] = in.tools[i];
      tools[i].time = static_cast<double>(steps) * dt;
    }
    double compute = 0.0;
    step_model({tools.data(), m_count}, dt, {forces.data(), m_count}, compute);
    m_model_timing.compute.add(compute);
    ModelOutput& out = m_from_model.write_slot();
    out.time = in.time;
    out.compute = compute;
    out.forces = forces;
    m_from_model.publish();
    ++steps;
    return true;
  });
  m_model_steps = steps;
}

ServoReport ServoLoop::run() {
  std::thread model;
  if (m_settings.model_rate > 0.0) model = std::thread([this] { model_thread(); });
  std::thread servo([this] { servo_thread(); });
  servo.join();
  if (model.joinable()) model.join();

  ServoReport report;
  report.realtime = m_realtime;
  report.timing = m_timing;
  report.model_timing = m_model_timing;
  for (std::size_t i = 0; i < m_count; ++i) {
    report.links.push_back(m_devices[i]->counters());
    report.safety.push_back(m_safety[i].counters());
    report.injected_energy.push_back(m_injected[i]);
  }
  report.model_steps = m_model_steps;
  report.model_steps_over_budget = m_model_over_budget;
  report.model_steps_over_period = m_model_over_period;
  report.records_dropped = m_recorder ? m_recorder->dropped() : 0;
  report.emergency_stopped = m_emergency;
  return report;
}

} // namespace kerf
