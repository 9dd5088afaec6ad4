#include "realtime/haptics/safety_layer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {
void require_positive(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string("safety layer: ") + name + " must be positive and finite (got " +
                                std::to_string(value) + ")");
}
} // namespace

SafetyLayer::SafetyLayer(const SafetyLimits& limits) : m_limits(limits) {
  require_positive(limits.max_force, "max_force [N]");
  require_positive(limits.max_force_rate, "max_force_rate [N/s]");
  require_positive(limits.ramp_time, "ramp_time [s]");
  require_positive(limits.watchdog_timeout, "watchdog_timeout [s]");
}

void SafetyLayer::start(double now) noexcept {
  m_started = true;
  m_stopping = false;
  m_start_time = now;
}

void SafetyLayer::stop(double now) noexcept {
  if (m_stopping) return;
  m_gain_at_stop = gain(now);
  m_stopping = true;
  m_stop_time = now;
}

double SafetyLayer::gain(double now) const noexcept {
  if (!m_started) return 0.0;
  // Ramp in: g = (t - t_start) / T_ramp, limited to [0, 1].
  const double in = std::clamp((now - m_start_time) / m_limits.ramp_time, 0.0, 1.0);
  if (!m_stopping) return in;
  // Ramp out from the gain at stop: g = g_stop (1 - (t - t_stop) / T_ramp), limited to [0, g_stop].
  return std::clamp(m_gain_at_stop * (1.0 - (now - m_stop_time) / m_limits.ramp_time), 0.0, m_gain_at_stop);
}

bool SafetyLayer::stopped(double now) const noexcept { return m_stopping && gain(now) == 0.0; }

Eigen::Vector3d SafetyLayer::filter(const Eigen::Vector3d& desired, double now, double link_age, double dt,
                                    double device_max_force, std::uint32_t& status) noexcept {
  status = 0;
  // 1. Emergency stop and watchdog: zero at once.
  if (m_emergency) {
    ++m_counters.emergency;
    status |= safety_emergency_stop;
    m_previous.setZero();
    return m_previous;
  }
  // A state watchdog_timeout old or older is silence (a NaN age too). The servo loop's clock is
  // its deadlines in whole nanoseconds, so n periods of age are n T up to the rounding of a
  // difference of two doubles: the 1 ns of slack makes the n-th tick trip whatever that rounding.
  constexpr double clock_slack = 1e-9; // [s]
  if (!(link_age < m_limits.watchdog_timeout - clock_slack)) {
    ++m_counters.watchdog;
    status |= safety_watchdog;
    m_previous.setZero();
    return m_previous;
  }
  // 2. NaN/Inf guard.
  Eigen::Vector3d target = desired;
  if (!target.allFinite()) {
    ++m_counters.non_finite;
    status |= safety_non_finite;
    target.setZero();
  }
  // 3. Ramp.
  const double g = gain(now);
  if (g < 1.0) status |= safety_ramping;
  if (m_stopping && g == 0.0) status |= safety_stopped;
  target *= g;
  // 4. Clamp to F_max = min(configured, declared); a device that declared nothing gets nothing.
  const double f_max = std::isfinite(device_max_force) ? std::clamp(device_max_force, 0.0, m_limits.max_force) : 0.0;
  const double magnitude = target.norm();
  if (magnitude > f_max) {
    target *= magnitude > 0.0 ? f_max / magnitude : 0.0;
    ++m_counters.clamped;
    status |= safety_clamped;
  }
  // 5. Rate limit: |F_k - F_{k-1}| <= rate dt.
  const double max_step = m_limits.max_force_rate * std::max(dt, 0.0);
  const Eigen::Vector3d step = target - m_previous;
  const double step_norm = step.norm();
  if (step_norm > max_step) {
    m_previous += step * (max_step / step_norm);
    ++m_counters.rate_limited;
    status |= safety_rate_limited;
  } else {
    m_previous = target;
  }
  // The clamp has priority over the rate limit when F_max itself dropped (a device declaring less).
  if (const double n = m_previous.norm(); n > f_max) m_previous *= f_max / n;
  if (!m_previous.allFinite()) m_previous.setZero(); // unreachable with finite limits; kept as the last guard
  return m_previous;
}

} // namespace kerf
