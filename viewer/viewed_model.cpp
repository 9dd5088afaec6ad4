#include "viewer/viewed_model.hpp"

#include <sys/resource.h>

#include <chrono>
#include <stdexcept>

namespace kerf {

ViewedModel::ViewedModel(ToolModel& model, ModelAdapter& adapter, double frame_period)
    : m_model(model), m_adapter(adapter), m_period(frame_period) {
  if (!(frame_period > 0.0))
    throw std::invalid_argument("viewer: frame period must be > 0 s, got " + std::to_string(frame_period));
  if (model.tool_count() > max_session_tools)
    throw std::invalid_argument("viewer: model " + std::string(model.name()) + " has " +
                                std::to_string(model.tool_count()) + " tools; a session takes at most " +
                                std::to_string(max_session_tools));
  // Reserve the three slots of the triple buffer: each publish hands the writer a slot the
  // reader is not holding, and the update after it hands the reader the one just filled.
  for (int k = 0; k < 3; ++k) {
    m_adapter.reserve(m_frames.write_slot().model);
    m_frames.write_slot().tool_count = model.tool_count();
    m_frames.publish();
    m_frames.update();
  }
}

void ViewedModel::reset() {
  m_model.reset();
  m_time = 0.0;
  m_next = 0.0;
}

void ViewedModel::step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept {
  m_model.step(tools, dt, forces);
  m_time += dt;
  const std::size_t n = std::min<std::size_t>(tools.size(), max_session_tools);
  for (std::size_t i = 0; i < n; ++i) {
    m_last_tools[i] = tools[i];
    m_last_forces[i] = forces[i];
  }
  if (m_time >= m_next) {
    publish_frame();
    m_next = m_time + m_period;
  }
}

void ViewedModel::publish_frame() noexcept {
  // The stepping thread's voluntary context switches before and after: one system call each
  // (no allocation, no lock; ~1 us at display rate).
  rusage before{};
  const bool counted = ::getrusage(RUSAGE_THREAD, &before) == 0;
  const auto begin = std::chrono::steady_clock::now();
  ViewFrame& f = m_frames.write_slot();
  f.tool_count = std::min(m_model.tool_count(), max_session_tools);
  f.time = f.tool_count > 0 ? m_last_tools[0].time : m_time; // the sample's time (rig or trajectory clock)
  f.sequence = ++m_sequence;
  for (std::size_t i = 0; i < static_cast<std::size_t>(f.tool_count); ++i) {
    f.tool_position[i] = m_last_tools[i].position;
    f.force[i] = m_last_forces[i];
  }
  if (m_timing) {
    f.servo.ticks = m_timing->ticks;
    f.servo.overruns = m_timing->overruns;
    f.servo.missed_deadlines = m_timing->missed_deadlines;
    f.servo.tick_mean = m_timing->tick.mean();
    f.servo.tick_max = m_timing->tick.max();
  }
  m_adapter.capture(f.model);
  m_frames.publish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  if (seconds > m_max_capture) m_max_capture = seconds;
  rusage after{};
  if (counted && ::getrusage(RUSAGE_THREAD, &after) == 0 && after.ru_nvcsw > before.ru_nvcsw) ++m_blocked;
}

} // namespace kerf
