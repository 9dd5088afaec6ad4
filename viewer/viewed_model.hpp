#pragma once
// ViewedModel: a ToolModel that steps another one and, at display rate, publishes a ViewFrame of
// it through a TripleBuffer for the render thread. It sits where the model sits (in the servo
// loop, or in an offline stepping), so the snapshot is taken in the model's own thread between
// two steps: no lock, no allocation, nothing the servo thread waits for. The render thread only
// ever reads the newest complete frame (triple_buffer.hpp).

#include "realtime/haptics/timing_statistics.hpp"
#include "realtime/haptics/triple_buffer.hpp"
#include "realtime/tool_model.hpp"
#include "viewer/model_adapter.hpp"

namespace kerf {

class ViewedModel final : public ToolModel {
public:
  /// Steps `model`, snapshotting it through `adapter` every `frame_period` [s] of model time
  /// (1/60 s: a display's rate). Reserves all three frames of the buffer (allocates).
  /// std::invalid_argument if frame_period <= 0 or the model has more tools than a session.
  ViewedModel(ToolModel& model, ModelAdapter& adapter, double frame_period);

  [[nodiscard]] std::string_view name() const override { return m_model.name(); }
  [[nodiscard]] int tool_count() const override { return m_model.tool_count(); }
  void reset() override;
  /// The inner model's step, then a snapshot when a frame period has passed. Allocation-free.
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  /// Servo statistics to copy into each frame, read in the stepping thread: give the servo
  /// loop's own statistics only when the model steps in the servo thread (single-rate). May be null.
  void set_servo_timing(const TimingStatistics* timing) noexcept { m_timing = timing; }

  /// Publishes a snapshot now (of the last step). Allocation-free; the stepping thread only.
  void publish_frame() noexcept;

  /// Render thread: takes the newest published frame if there is a newer one; returns whether it did.
  bool update() noexcept { return m_frames.update(); }
  /// Render thread: the newest frame taken by update().
  [[nodiscard]] const ViewFrame& frame() const noexcept { return m_frames.read_slot(); }

  /// Wall time of the longest snapshot so far [s] (the cost the view adds to one step).
  [[nodiscard]] double max_capture_seconds() const noexcept { return m_max_capture; }
  [[nodiscard]] std::uint64_t frames_published() const noexcept { return m_sequence; }
  /// Snapshots during which the stepping thread gave up its CPU voluntarily (getrusage
  /// RUSAGE_THREAD: its voluntary context switches across capture and publish), i.e. waited for
  /// something: a lock, a page brought in, a system call that sleeps. The snapshot only copies
  /// numbers into a slot of a wait-free triple buffer, so this stays 0 whatever the render thread
  /// does; a snapshot that waited on the render side would show here. (Being preempted is not
  /// waiting: involuntary switches are the machine's, not counted.)
  [[nodiscard]] std::uint64_t blocked_snapshots() const noexcept { return m_blocked; }

private:
  ToolModel& m_model;
  ModelAdapter& m_adapter;
  double m_period;
  double m_time = 0.0;
  double m_next = 0.0;
  std::uint64_t m_sequence = 0;
  double m_max_capture = 0.0;
  std::uint64_t m_blocked = 0;
  const TimingStatistics* m_timing = nullptr;
  std::array<ToolState, max_session_tools> m_last_tools{};
  std::array<ForceSample, max_session_tools> m_last_forces{};
  TripleBuffer<ViewFrame> m_frames;
};

} // namespace kerf
