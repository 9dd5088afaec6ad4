#include "viewer/live_session.hpp"

#include "viewer/viewed_model.hpp"

#include "realtime/haptics/realtime_scheduling.hpp"

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

namespace kerf {

LiveViewReport run_live_view(ToolModel& model, const ToolModel& shown, const TetMesh& mesh,
                             std::span<HapticDevice* const> devices, const LiveViewSettings& settings,
                             std::atomic<ServoLoop*>* running) {
  if (!(settings.display_rate > 0.0 && settings.display_rate <= 240.0))
    throw std::invalid_argument("viewer: display rate must be in (0, 240] Hz, got " + std::to_string(settings.display_rate));
  LiveViewReport out;
  if (!settings.view) {
    ServoLoop loop(model, devices, settings.servo, nullptr);
    if (running) running->store(&loop);
    out.servo = loop.run();
    if (running) running->store(nullptr);
    return out;
  }

  // Mesa's software rasteriser (llvmpipe, what Xvfb and machines without a GPU render with)
  // starts one rendering thread per core unless LP_NUM_THREADS says otherwise; beside a servo
  // thread on 2 cores they cost it deadlines (sponge_cut_constant/voxel at 1 kHz: overruns in 3
  // of 7 viewed sessions with them, in 1 of 7 without; docs/viewer.md). Rendered in this thread
  // alone the frames still come at about 60 Hz. Read when the first GL context is made, so set
  // here; a value the user set is kept.
  ::setenv("LP_NUM_THREADS", "0", 0);
  // The servo thread gets a CPU of its own and the view stays off it: this thread renders, and the
  // threads it starts (the GL driver's, the multi-rate model thread, which the loop starts from
  // here) inherit its mask. A guest kernel that does not preempt system calls (PREEMPT_NONE)
  // otherwise wakes the servo late whenever the render thread is in the kernel on the CPU the
  // servo wakes on. The servo's CPU is settings.servo.cpu when set, else the last of the
  // process's CPUs; with one CPU nothing moves.
  ServoSettings servo_settings = settings.servo;
  if (servo_settings.realtime && servo_settings.cpu < 0) servo_settings.cpu = last_of_several_cpus();
  struct RestoreCpus {
    CpuMask mask;
    ~RestoreCpus() { restore_cpus(mask); }
  } render_cpus{keep_off_cpu(servo_settings.cpu)};
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(shown, mesh);
  ViewedModel viewed(model, *adapter, 1.0 / settings.display_rate);
  ViewWindowSettings window_settings = settings.window;
  window_settings.offscreen = !settings.interactive;
  ViewWindow window(window_settings, 1, false);
  FrameView view(window.body_renderer(0), *adapter, settings.frame);
  frame_camera(window.camera(), view.bounds(), settings.camera, window.body_aspect());

  // One frame before the servo starts (the body at rest): the first render compiles the shaders
  // and allocates the GL buffers and Mesa's threads, the longest and most memory-hungry frame,
  // which would otherwise run beside the servo's first ticks.
  view.show(viewed.frame());
  window.render();

  ServoLoop loop(viewed, devices, servo_settings, nullptr);
  // The servo statistics are read in the thread that steps the model: only when that is the
  // servo thread itself (single-rate) are they the servo's own, race-free.
  if (settings.servo.model_rate <= 0.0) viewed.set_servo_timing(&loop.timing());
  if (running) running->store(&loop);
  std::atomic<bool> done{false};
  std::thread servo([&] {
    out.servo = loop.run();
    done.store(true, std::memory_order_release);
  });

  using Clock = std::chrono::steady_clock;
  double render_total = 0.0;
  double render_cpu_total = 0.0;
  auto draw = [&] {
    if (!viewed.update()) return;
    const auto begin = Clock::now();
    const double cpu_begin = thread_cpu_seconds();
    view.show(viewed.frame());
    window.render();
    render_cpu_total += thread_cpu_seconds() - cpu_begin;
    const double seconds = std::chrono::duration<double>(Clock::now() - begin).count();
    render_total += seconds;
    out.max_render_seconds = std::max(out.max_render_seconds, seconds);
    ++out.frames_rendered;
  };
  const double period = 1.0 / settings.display_rate;
  try {
    if (settings.interactive) {
      window.run(
          [&] {
            draw();
            return !done.load(std::memory_order_acquire);
          },
          period,
          [&](const std::string& key) {
            if (key == "o") view.toggle_overlay();
          });
      loop.request_stop(); // the window was closed (or q): end the session with a ramp out
    } else {
      auto next = Clock::now();
      while (!done.load(std::memory_order_acquire)) {
        next += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
        std::this_thread::sleep_until(next);
        draw();
      }
    }
  } catch (...) {
    loop.request_emergency_stop();
    servo.join();
    if (running) running->store(nullptr);
    throw;
  }
  servo.join();
  if (running) running->store(nullptr);
  draw(); // the last frame published
  if (!settings.screenshot.empty()) {
    view.show(viewed.frame());
    window.write_png(settings.screenshot);
  }
  out.frames_published = viewed.frames_published();
  out.max_capture_seconds = viewed.max_capture_seconds();
  out.blocked_snapshots = viewed.blocked_snapshots();
  out.mean_render_seconds = out.frames_rendered ? render_total / static_cast<double>(out.frames_rendered) : 0.0;
  out.mean_render_cpu_seconds = out.frames_rendered ? render_cpu_total / static_cast<double>(out.frames_rendered) : 0.0;
  return out;
}

} // namespace kerf
