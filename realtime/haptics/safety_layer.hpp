#pragma once
// The safety layer between a model and a device (../shared/DESIGN.md, "Realtime contract"): it
// holds whatever the model does. Per tick, in this order:
//   1. emergency stop latched, or the link silent for the watchdog time or longer -> F = 0 now;
//   2. NaN/Inf guard: a non-finite model force is replaced by zero;
//   3. ramp: F_target = g(t) F_model, g rising linearly 0 -> 1 over the ramp time after start()
//      and falling linearly to 0 over the ramp time after stop();
//   4. clamp: |F_target| <= F_max = min(configured maximum, the device's declared maximum),
//      scaling the vector (its direction is kept);
//   5. force-rate limit: |F_k - F_{k-1}| <= rate dt, stepping from the previous output toward
//      the target. Both ends lie in the ball |F| <= F_max, so the output does too (convexity).
// Zeroing in step 1 is immediate (not rate limited): removing force is the safe direction.

#include "realtime/haptics/device_protocol.hpp"
#include "realtime/haptics/device_specs.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace kerf {

/// Limits of one device's force channel. All must be positive and finite.
struct SafetyLimits {
  double max_force = 0.0;        ///< [N] configured maximum; the device's declared one also applies
  double max_force_rate = 0.0;   ///< [N/s] largest change of the commanded force per second
  double ramp_time = 0.0;        ///< [s] duration of the linear ramp in and out
  double watchdog_timeout = 0.0; ///< [s] a device state this old or older is silence: force is zeroed
};

/// The rig's safety defaults, defined here once (`kerf-rig haptic`, `kerf view --device`, the tests):
///   - max_force 8.5 N: the default device's maximum force (default_device_model, device_table);
///   - max_force_rate 1000 N/s: the full 8.5 N in 8.5 ms, no step a hand feels as a blow;
///   - ramp_time 0.2 s: force fades in and out over 200 servo ticks at 1 kHz;
///   - watchdog_timeout 10 ms: at 1 kHz, zero force on the 10th tick without a new device state.
inline constexpr SafetyLimits default_safety_limits{device_specs_constexpr(default_device_model).max_force, 1000.0,
                                                    0.2, 0.010};

/// The default watchdog time at servo rate `rate` [Hz]: default_safety_limits' 10 ms, but never
/// below two servo periods (a device sending at the servo rate leaves one period between states,
/// and a single late state must not zero the force). ServoLoop rejects a shorter one.
[[nodiscard]] constexpr double default_watchdog_timeout(double rate) noexcept {
  return default_safety_limits.watchdog_timeout > 2.0 / rate ? default_safety_limits.watchdog_timeout : 2.0 / rate;
}

/// The default limits for the device `specs` (its maximum force; the rest as default_safety_limits).
[[nodiscard]] constexpr SafetyLimits default_safety_limits_for(const DeviceSpecs& specs) noexcept {
  SafetyLimits limits = default_safety_limits;
  limits.max_force = specs.max_force;
  return limits;
}

/// Counts of what the layer did over a session (ticks).
struct SafetyCounters {
  std::uint64_t non_finite = 0;   ///< ticks with a NaN/Inf model force
  std::uint64_t clamped = 0;      ///< ticks where the clamp acted
  std::uint64_t rate_limited = 0; ///< ticks where the rate limit acted
  std::uint64_t watchdog = 0;     ///< ticks zeroed by the watchdog
  std::uint64_t emergency = 0;    ///< ticks zeroed by the emergency stop
};

/// One device's safety state machine. Allocation-free; `filter` is noexcept.
class SafetyLayer {
public:
  /// Throws std::invalid_argument naming the limit that is not positive and finite.
  explicit SafetyLayer(const SafetyLimits& limits);
  SafetyLayer() = delete; // a zero limit would silently disable the device

  /// Ramp in starts at `now` [s] (also clears a finished ramp out; not an emergency stop).
  void start(double now) noexcept;
  /// Ramp out starts at `now` [s] from the current gain.
  void stop(double now) noexcept;
  /// Latches the emergency stop: zero force from the next filter() on, until a new layer.
  void emergency_stop() noexcept { m_emergency = true; }
  [[nodiscard]] bool emergency_stopped() const noexcept { return m_emergency; }
  /// True once a ramp out has reached zero gain.
  [[nodiscard]] bool stopped(double now) const noexcept;

  /// The force to command at time `now` [s] for the model's `desired` force [N], `link_age` [s]
  /// since the device's last accepted state, `dt` [s] since the previous tick, and the device's
  /// declared maximum force [N] (0 if unknown: then nothing is passed). Writes SafetyStatus bits
  /// to `status`. Never returns a non-finite vector.
  Eigen::Vector3d filter(const Eigen::Vector3d& desired, double now, double link_age, double dt,
                         double device_max_force, std::uint32_t& status) noexcept;

  /// The ramp gain g(now) in [0, 1].
  [[nodiscard]] double gain(double now) const noexcept;
  [[nodiscard]] const SafetyLimits& limits() const noexcept { return m_limits; }
  [[nodiscard]] const SafetyCounters& counters() const noexcept { return m_counters; }
  [[nodiscard]] const Eigen::Vector3d& last_output() const noexcept { return m_previous; }

private:
  SafetyLimits m_limits;
  SafetyCounters m_counters;
  Eigen::Vector3d m_previous = Eigen::Vector3d::Zero();
  bool m_started = false;
  bool m_stopping = false;
  bool m_emergency = false;
  double m_start_time = 0.0;
  double m_stop_time = 0.0;
  double m_gain_at_stop = 0.0;
};

} // namespace kerf
