#pragma once
// A live session with the view beside it (`kerf view SCENE --model M`): the servo loop runs the
// model wrapped in a ViewedModel on its own thread(s), exactly as `kerf-rig haptic` runs it, while
// the calling thread renders the newest ViewFrame at display rate. The render thread never
// touches the model and the servo thread never waits for the render thread.

#include "realtime/haptics/servo_loop.hpp"
#include "viewer/frame_view.hpp"
#include "viewer/view_window.hpp"

#include <atomic>
#include <filesystem>

namespace kerf {

struct LiveViewSettings {
  ServoSettings servo;
  bool view = true;              ///< false: the servo session alone (what the view is compared against)
  bool interactive = true;       ///< an on-screen window with an interactor; false: off-screen rendering at display rate
  double display_rate = 60.0;    ///< frames per second the view renders and the model is snapshot [Hz]
  ViewWindowSettings window;
  CameraView camera = CameraView::oblique;
  FrameViewSettings frame;
  std::filesystem::path screenshot; ///< written from the last frame when the session ends (empty: none)
};

struct LiveViewReport {
  ServoReport servo;
  std::uint64_t frames_published = 0;  ///< snapshots the model's thread took
  std::uint64_t frames_rendered = 0;   ///< frames the view drew
  double max_capture_seconds = 0.0;    ///< longest snapshot (time the view adds to one model step) [s]
  std::uint64_t blocked_snapshots = 0; ///< snapshots in which the stepping thread waited (ViewedModel::blocked_snapshots)
  double mean_render_seconds = 0.0;    ///< render thread, per frame drawn, wall clock [s]
  double mean_render_cpu_seconds = 0.0; ///< render thread, per frame drawn, its own CPU time [s]
  double max_render_seconds = 0.0;
};

/// Runs one session: `model` (built on `mesh`) driven by `devices` (one per tool), viewed when
/// settings.view through the adapter of `shown` (make_model_adapter): `model` itself, or the
/// model proper that `model` wraps (BuiltModel::core_model()). `running`, when given, holds the
/// loop while it runs (for a signal handler's emergency stop). In an interactive window: key o
/// toggles the overlay, q (or closing the window) ends the session with a ramp out.
LiveViewReport run_live_view(ToolModel& model, const ToolModel& shown, const TetMesh& mesh,
                             std::span<HapticDevice* const> devices, const LiveViewSettings& settings,
                             std::atomic<ServoLoop*>* running = nullptr);

} // namespace kerf
