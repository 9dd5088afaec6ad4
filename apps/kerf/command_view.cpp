// kerf view: the viewer (viewer/, docs/viewer.md).
//   kerf view SCENE --model M [--device ADDRESS...]   a live session with the view beside the servo loop
//   kerf view SCENE --model M --screenshot F --at T    the model stepped off line to T, one picture
//   kerf view RUN_DIR [RUN_DIR...]                     recorded runs side by side, shared time slider

#include "apps/kerf/commands.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/quantity.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/haptics/replay_device.hpp"
#include "viewer/live_session.hpp"
#include "viewer/offline_stepping.hpp"
#include "viewer/run_replay.hpp"
#include "viewer/viewed_model.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <unistd.h>

namespace kerf::cli {

namespace {

struct ViewOptions {
  std::vector<std::string> targets;
  std::string model;
  std::string integrator;
  std::vector<std::string> devices;
  double rate = 1000.0;
  double model_rate = 0.0;
  double duration = -1.0;
  double max_force = default_safety_limits.max_force;
  double force_rate = default_safety_limits.max_force_rate;
  double ramp = default_safety_limits.ramp_time;
  double watchdog = -1.0; ///< [s] < 0: default_watchdog_timeout(rate)
  bool no_realtime = false;
  std::string screenshot;
  double at = -1.0;
  std::string colouring = "displacement";
  std::string colour_max;
  std::string camera = "oblique";
  bool no_overlay = false;
  bool no_text = false;
  bool no_chart = false;
  bool offscreen = false;
  bool no_view = false;
  int width = 1280;
  int height = 800;
  double display_rate = 60.0;
};

std::atomic<ServoLoop*> viewed_loop{nullptr};

extern "C" void view_emergency_signal(int) {
  if (ServoLoop* loop = viewed_loop.load()) loop->request_emergency_stop();
}

Colouring parse_colouring(const std::string& name) {
  const auto c = colouring_from_string(name);
  if (!c) throw std::invalid_argument("view: --colour must be displacement or von-mises, got \"" + name + "\"");
  return *c;
}

CameraView parse_camera(const std::string& name) {
  const auto c = camera_view_from_string(name);
  if (!c) throw std::invalid_argument("view: --camera must be oblique or front, got \"" + name + "\"");
  return *c;
}

/// --colour-max: a length for displacement ("8 mm"), a stress for von Mises ("50 kPa"); "" = automatic.
double parse_colour_max(const std::string& text, Colouring colouring) {
  if (text.empty()) return 0.0;
  return parse_quantity(text, colouring == Colouring::displacement ? Dimension::length : Dimension::pressure);
}

std::vector<ToolGlyph> tool_glyphs(const Scene& scene) {
  std::vector<ToolGlyph> glyphs;
  for (const Tool& t : scene.tools) {
    ToolGlyph g;
    g.blade = t.kind == Tool::Kind::blade;
    g.radius = t.radius;
    g.blade_shape = t.blade;
    glyphs.push_back(g);
  }
  return glyphs;
}

FrameViewSettings frame_settings(const ViewOptions& o, const Scene& scene, const std::string& model) {
  FrameViewSettings s;
  s.title = scene.name + " / " + model;
  for (const Tool& t : scene.tools) s.tool_names.push_back(t.name);
  s.tools = tool_glyphs(scene);
  s.colouring = parse_colouring(o.colouring);
  s.elastic = {scene.material.youngs_modulus, scene.material.poisson_ratio};
  s.colour_max = parse_colour_max(o.colour_max, s.colouring);
  s.overlay = !o.no_overlay;
  s.text = !o.no_text;
  return s;
}

/// Writes a sampled trajectory as the replay device's CSV (t,px,py,pz; s and m).
void write_trajectory_csv(const SampledTrajectory& t, const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("view: cannot write " + file.string());
  out.precision(17);
  out << "t,px,py,pz\n";
  for (const ToolState& s : t.samples)
    out << s.time << ',' << s.position.x() << ',' << s.position.y() << ',' << s.position.z() << '\n';
  if (!out) throw std::runtime_error("view: writing " + file.string() + " failed");
}

/// `kerf view SCENE --model M --screenshot F [--at T]`: off line, deterministic.
void scene_screenshot(const ViewOptions& o, const Scene& scene, const TetMesh& mesh, BuiltModel& built) {
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(built, mesh);
  ViewedModel viewed(*built.model, *adapter, 1.0);
  ViewWindowSettings ws;
  ws.width = o.width;
  ws.height = o.height;
  ws.offscreen = true;
  ViewWindow window(ws, 1, false);
  FrameView view(window.body_renderer(0), *adapter, frame_settings(o, scene, o.model));
  const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    const double r = scene.tools[i].kind == Tool::Kind::sphere ? scene.tools[i].radius : 0.0;
    for (const ToolState& s : trajectories[i].samples) {
      view.extend_bounds(s.position - Eigen::Vector3d::Constant(r));
      view.extend_bounds(s.position + Eigen::Vector3d::Constant(r));
    }
  }
  const double at = o.at >= 0.0 ? o.at : 0.0;
  const std::array<double, 1> times{at};
  step_through(viewed, trajectories, times, [&](const ViewFrame& f) { view.show(f); },
               [&](double force) { view.note_force(force); });
  // The camera frames the body as shown too (torn pieces carried beyond the rest block).
  for (Eigen::Index i = 0; i < view.shown().points.rows(); ++i) view.extend_bounds(view.shown().points.row(i).transpose());
  frame_camera(window.camera(), view.bounds(), parse_camera(o.camera), window.body_aspect());
  window.write_png(o.screenshot);
  std::printf("wrote %s (%s / %s at t = %.4f s)\n", o.screenshot.c_str(), scene.name.c_str(), o.model.c_str(), at);
}

void scene_live(const ViewOptions& o, const Scene& scene, const TetMesh& mesh, BuiltModel& built) {
  // Devices: the ones given, else each tool's scripted trajectory replayed (replay:FILE).
  std::vector<std::unique_ptr<HapticDevice>> devices;
  std::vector<HapticDevice*> raw;
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / ("kerf_view_" + std::to_string(::getpid()));
  double duration = o.duration;
  if (o.devices.empty()) {
    std::filesystem::create_directories(scratch);
    const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
    double longest = 0.0;
    for (std::size_t i = 0; i < trajectories.size(); ++i) {
      const std::filesystem::path csv = scratch / (scene.tools[i].name + ".csv");
      write_trajectory_csv(trajectories[i], csv);
      devices.push_back(open_device("replay:" + csv.string()));
      longest = std::max(longest, trajectories[i].duration());
    }
    if (duration < 0.0) duration = longest;
  } else {
    if (o.devices.size() != scene.tools.size())
      throw std::invalid_argument("view: scene " + scene.name + " has " + std::to_string(scene.tools.size()) +
                                  " tool(s); give one --device per tool, in scene order (got " +
                                  std::to_string(o.devices.size()) + ")");
    for (const std::string& address : o.devices) devices.push_back(open_device(address));
    if (duration < 0.0) duration = 0.0;
  }
  for (auto& d : devices) raw.push_back(d.get());

  LiveViewSettings s;
  s.servo.rate = o.rate;
  s.servo.model_rate = o.model_rate;
  s.servo.duration = duration;
  s.servo.safety = {o.max_force, o.force_rate, o.ramp, o.watchdog < 0.0 ? default_watchdog_timeout(o.rate) : o.watchdog};
  s.servo.realtime = !o.no_realtime;
  s.servo.on_realtime = [&o](const RealtimeSetup& r) {
    if (o.no_realtime) std::fprintf(stderr, "kerf view: real-time scheduling not requested (--no-realtime)\n");
    else if (r.fifo && r.locked) std::fprintf(stderr, "kerf view: servo thread SCHED_FIFO, memory locked\n");
    else std::fputs(r.warnings.c_str(), stderr);
  };
  s.view = !o.no_view;
  s.interactive = !o.offscreen;
  s.display_rate = o.display_rate;
  s.window.width = o.width;
  s.window.height = o.height;
  s.window.title = "kerf view " + scene.name + " / " + o.model;
  s.camera = parse_camera(o.camera);
  s.frame = frame_settings(o, scene, o.model);
  s.screenshot = o.screenshot;

  struct sigaction action {};
  action.sa_handler = view_emergency_signal;
  sigemptyset(&action.sa_mask);
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &action, &old_int);
  sigaction(SIGTERM, &action, &old_term);
  std::printf("%s / %s at %.0f Hz, view at %.0f Hz%s; Ctrl-C is an emergency stop\n", scene.name.c_str(),
              o.model.c_str(), o.rate, o.display_rate,
              duration > 0.0 ? (", " + std::to_string(duration) + " s").c_str() : ", until the window is closed");
  std::fflush(stdout);
  LiveViewReport report;
  try {
    report = run_live_view(*built.model, built.core_model(), mesh, raw, s, &viewed_loop);
  } catch (...) {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    if (o.devices.empty()) std::filesystem::remove_all(scratch);
    throw;
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  if (o.devices.empty()) std::filesystem::remove_all(scratch);

  const TimingStatistics& t = report.servo.timing;
  std::printf("%s: %llu ticks, %llu model steps, %llu overruns, %llu missed deadlines%s\n",
              report.servo.emergency_stopped ? "emergency stop" : "session ended",
              static_cast<unsigned long long>(t.ticks), static_cast<unsigned long long>(report.servo.model_steps),
              static_cast<unsigned long long>(t.overruns), static_cast<unsigned long long>(t.missed_deadlines),
              report.servo.realtime.fifo ? " (SCHED_FIFO)" : "");
  std::printf("  whole tick     p50 %8.2f us  p99 %8.2f us  max %8.2f us\n", t.tick.percentile(50) * 1e6,
              t.tick.percentile(99) * 1e6, t.tick.max() * 1e6);
  // Woken after the deadline (the scheduler's latency): a tick overruns when this plus its work
  // passes the next deadline.
  std::printf("  woken late     p50 %8.2f us  p99 %8.2f us  max %8.2f us\n", t.lateness.percentile(50) * 1e6,
              t.lateness.percentile(99) * 1e6, t.lateness.max() * 1e6);
  if (o.no_view) std::printf("view: off (--no-view)\n");
  else
    std::printf("view: %llu snapshots (longest %.2f us in the %s thread, %llu waited), %llu frames drawn (mean %.2f ms, "
                "max %.2f ms, render thread CPU %.2f ms a frame)\n",
                static_cast<unsigned long long>(report.frames_published), report.max_capture_seconds * 1e6,
                o.model_rate > 0.0 ? "model" : "servo", static_cast<unsigned long long>(report.blocked_snapshots),
                static_cast<unsigned long long>(report.frames_rendered), report.mean_render_seconds * 1e3,
                report.max_render_seconds * 1e3, report.mean_render_cpu_seconds * 1e3);
  if (!o.screenshot.empty()) std::printf("wrote %s\n", o.screenshot.c_str());
}

void run_scene_view(const ViewOptions& o) {
  if (o.targets.size() != 1)
    throw std::invalid_argument("view: give one scene (or run directories, each holding a manifest.json)");
  if (o.model.empty()) throw std::invalid_argument("view: a scene needs --model M (see `kerf models`)");
  const Scene scene = read_scene(resolve_scene(o.targets.front()));
  require_model_for_scene(o.model, scene);
  const TetMesh mesh = scene_mesh(scene);
  ModelOptions options;
  if (!o.integrator.empty()) options["integrator"] = o.integrator;
  BuiltModel built = make_model(o.model, scene, mesh, options);
  if (o.no_view && !o.screenshot.empty()) throw std::invalid_argument("view: --no-view takes no --screenshot");
  if (!o.screenshot.empty() && o.devices.empty() && !o.offscreen) scene_screenshot(o, scene, mesh, built);
  else scene_live(o, scene, mesh, built);
}

void run_view(const ViewOptions& o) {
  if (o.targets.empty()) throw std::invalid_argument("view: give a scene or run directories");
  const bool runs = std::filesystem::is_directory(o.targets.front());
  if (!runs) {
    run_scene_view(o);
    return;
  }
  if (!o.model.empty() || !o.devices.empty())
    throw std::invalid_argument("view: --model and --device are for a scene, not for run directories");
  ReplaySettings s;
  for (const std::string& t : o.targets) s.runs.push_back(t);
  s.colouring = parse_colouring(o.colouring);
  s.colour_max = parse_colour_max(o.colour_max, s.colouring);
  s.camera = parse_camera(o.camera);
  s.overlay = !o.no_overlay;
  s.text = !o.no_text;
  s.chart = !o.no_chart;
  s.window.width = o.width;
  s.window.height = o.height;
  s.window.offscreen = !o.screenshot.empty();
  s.window.title = "kerf view (replay)";
  s.screenshot = o.screenshot;
  s.at = o.at;
  replay_runs(s);
  if (!o.screenshot.empty()) std::printf("wrote %s\n", o.screenshot.c_str());
}

} // namespace

void add_view_command(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  auto* c = app.add_subcommand("view", "see a model live beside the servo loop, or recorded runs side by side "
                                       "(docs/viewer.md)");
  c->add_option("target", o->targets, "a scene (file or name) with --model, or run directories (kerf run/reference output)")
      ->required();
  c->add_option("--model", o->model, "model name (scene mode; see `kerf models`)");
  c->add_option("--integrator", o->integrator, "springs: explicit|implicit|static");
  c->add_option("--device", o->devices,
                "udp://HOST:PORT or replay:FILE, one per tool in scene order (default: the scene's trajectories replayed)");
  c->add_option("--rate", o->rate, "servo rate [Hz]")->capture_default_str();
  c->add_option("--model-rate", o->model_rate,
                "run the model in its own thread at this rate [Hz] (< rate; the servo interpolates); 0 = in the servo "
                "thread")
      ->capture_default_str();
  c->add_option("--duration", o->duration, "seconds until the ramp out (default: the trajectory's length; 0 with "
                                           "--device: until the window is closed)");
  c->add_option("--max-force", o->max_force, "force clamp [N]")->capture_default_str();
  c->add_option("--force-rate", o->force_rate, "force-rate limit [N/s]")->capture_default_str();
  c->add_option("--ramp", o->ramp, "ramp in/out time [s]")->capture_default_str();
  c->add_option("--watchdog", o->watchdog,
                "zero force once the newest device state is this old [s] (default 10 ms, at least two servo periods)");
  c->add_flag("--no-realtime", o->no_realtime, "do not ask for SCHED_FIFO and locked memory");
  c->add_option("--screenshot", o->screenshot,
                "write a PNG off screen: a scene is stepped off line to --at (no servo loop); runs are shown at --at");
  c->add_option("--at", o->at, "time of the screenshot [s] (default: 0 for a scene, the end for runs)");
  c->add_option("--colour", o->colouring, "displacement or von-mises")->capture_default_str();
  c->add_option("--colour-max", o->colour_max, "top of the colour scale (\"8 mm\", \"50 kPa\"; default: automatic)");
  c->add_option("--camera", o->camera, "oblique or front")->capture_default_str();
  c->add_flag("--no-overlay", o->no_overlay, "start with the wire-frame overlay hidden (key o toggles it)");
  c->add_flag("--no-text", o->no_text, "no text or colour legend in the picture");
  c->add_flag("--no-chart", o->no_chart, "runs: no force-displacement chart below the views");
  c->add_flag("--offscreen", o->offscreen, "live session rendered off screen at display rate (no window)");
  c->add_flag("--no-view", o->no_view,
              "live: the same session without the view (no window, no snapshots), to compare the servo statistics");
  c->add_option("--width", o->width, "window width [px]")->capture_default_str();
  c->add_option("--height", o->height, "window height [px]")->capture_default_str();
  c->add_option("--display-rate", o->display_rate, "frames per second of the live view [Hz]")->capture_default_str();
  c->callback([o] { run_view(*o); });
}

} // namespace kerf::cli
