// The live rig's session (realtime/haptics, docs/haptic-rig.md): the safety limits from the
// options and the named device, the scene's model, one device per tool of the scene, in scene
// order; SIGINT/SIGTERM (or a device's e-stop button) is an emergency stop. Optionally through
// Colgate's virtual coupling (--coupling-stiffness, --coupling-damping, --virtual-mass).

#include "apps/kerf-rig/haptic_session.hpp"

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/haptics/device_specs.hpp"
#include "realtime/haptics/servo_loop.hpp"
#include "realtime/haptics/udp_device.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>

namespace kerf::cli {

namespace {

/// The session being run, for the signal handler (an atomic pointer: async-signal-safe to read).
std::atomic<ServoLoop*> running_loop{nullptr};

extern "C" void emergency_signal(int) {
  if (ServoLoop* loop = running_loop.load()) loop->request_emergency_stop();
}

void print_histogram(const char* name, const DurationHistogram& h) {
  std::printf("  %-14s p50 %8.2f us  p99 %8.2f us  p99.9 %8.2f us  max %8.2f us  (n = %llu)\n", name,
              h.percentile(50) * 1e6, h.percentile(99) * 1e6, h.percentile(99.9) * 1e6, h.max() * 1e6,
              static_cast<unsigned long long>(h.count()));
}

} // namespace

void run_haptic(const HapticOptions& o) {
  // The safety limits: the named device's maximum force unless --max-force asks for less (never
  // more), the watchdog at least two servo periods unless given.
  const DeviceSpecs& specs = device_specs(o.device_model);
  if (o.max_force_given && o.max_force > specs.max_force) {
    char message[256];
    std::snprintf(message, sizeof message, "haptic: --max-force %g N exceeds the %s's maximum force %g N (--device-model %s)",
                  o.max_force, std::string(specs.model).c_str(), specs.max_force, std::string(specs.name).c_str());
    throw std::invalid_argument(message);
  }
  SafetyLimits safety = default_safety_limits_for(specs);
  if (o.max_force_given) safety.max_force = o.max_force;
  safety.max_force_rate = o.force_rate;
  safety.ramp_time = o.ramp;
  safety.watchdog_timeout = o.watchdog_given ? o.watchdog : default_watchdog_timeout(o.rate);
  if (o.coupling.stiffness > specs.max_stiffness)
    std::fprintf(stderr, "kerf-rig: warning: coupling stiffness %.0f N/m is above the %s's stable %.0f N/m\n",
                 o.coupling.stiffness, std::string(specs.model).c_str(), specs.max_stiffness);
  std::printf("safety: %s, clamp %.3g N, force rate %.4g N/s, ramp %.3g s, watchdog %.3g ms\n",
              std::string(specs.model).c_str(), safety.max_force, safety.max_force_rate, safety.ramp_time,
              safety.watchdog_timeout * 1e3);

  const Scene scene = read_scene(resolve_scene(o.scene));
  require_model_for_scene(o.model, scene);
  if (o.devices.size() != scene.tools.size())
    throw std::invalid_argument("haptic: scene " + scene.name + " has " + std::to_string(scene.tools.size()) +
                                " tool(s); give one --device per tool, in scene order (got " +
                                std::to_string(o.devices.size()) + ")");
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model(o.model, scene, mesh);

  std::vector<std::unique_ptr<HapticDevice>> devices;
  std::vector<HapticDevice*> raw;
  std::vector<std::string> tool_names;
  for (std::size_t i = 0; i < o.devices.size(); ++i) {
    devices.push_back(open_device(o.devices[i]));
    raw.push_back(devices.back().get());
    tool_names.push_back(scene.tools[i].name);
    std::printf("tool %s <- device %s\n", scene.tools[i].name.c_str(), o.devices[i].c_str());
  }

  ServoSettings settings;
  settings.rate = o.rate;
  settings.model_rate = o.model_rate;
  settings.duration = o.duration;
  settings.safety = safety;
  settings.coupling = o.coupling;
  settings.realtime = !o.no_realtime;
  settings.on_realtime = [&o](const RealtimeSetup& r) {
    if (o.no_realtime) std::fprintf(stderr, "kerf-rig: real-time scheduling not requested (--no-realtime)\n");
    else if (r.fifo && r.locked) std::fprintf(stderr, "kerf-rig: servo thread SCHED_FIFO, memory locked\n");
    else std::fputs(r.warnings.c_str(), stderr);
  };
  std::unique_ptr<SessionRecorder> recorder;
  if (!o.record.empty()) {
    const double seconds = 2.0; // ring of 2 s of ticks: the writer drains it every 20 ms
    recorder = std::make_unique<SessionRecorder>(o.record, SessionHeader{o.rate, o.model, scene.name, tool_names},
                                                 static_cast<std::size_t>(seconds * o.rate));
  }
  ServoLoop loop(*built.model, raw, settings, recorder.get());

  struct sigaction action {};
  action.sa_handler = emergency_signal;
  sigemptyset(&action.sa_mask);
  struct sigaction old_int {}, old_term {};
  running_loop.store(&loop);
  sigaction(SIGINT, &action, &old_int);
  sigaction(SIGTERM, &action, &old_term);
  std::printf("%s / %s at %.0f Hz%s%s; Ctrl-C is an emergency stop\n", scene.name.c_str(), o.model.c_str(), o.rate,
              o.model_rate > 0.0 ? (", model thread at " + std::to_string(static_cast<int>(o.model_rate)) + " Hz").c_str()
                                 : "",
              o.duration > 0.0 ? (", " + std::to_string(o.duration) + " s").c_str() : ", until stopped");
  std::fflush(stdout);
  const ServoReport report = loop.run();
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  running_loop.store(nullptr);
  if (recorder) recorder->close();

  const TimingStatistics& t = report.timing;
  std::printf("%s: %llu ticks, %llu model steps, %llu overruns, %llu missed deadlines%s\n",
              report.emergency_stopped ? "emergency stop" : "session ended", static_cast<unsigned long long>(t.ticks),
              static_cast<unsigned long long>(report.model_steps), static_cast<unsigned long long>(t.overruns),
              static_cast<unsigned long long>(t.missed_deadlines), report.realtime.fifo ? " (SCHED_FIFO)" : "");
  print_histogram("wake lateness", t.lateness);
  print_histogram("period jitter", t.period_jitter);
  print_histogram("model compute", o.model_rate > 0.0 ? report.model_timing.compute : t.compute);
  std::printf("model steps over budget: %llu reported by the model (not converged in its bounded work), %llu longer than "
              "their period\n",
              static_cast<unsigned long long>(report.model_steps_over_budget),
              static_cast<unsigned long long>(report.model_steps_over_period));
  print_histogram("whole tick", t.tick);
  for (std::size_t i = 0; i < report.links.size(); ++i) {
    const LinkCounters& c = report.links[i];
    const SafetyCounters& s = report.safety[i];
    std::printf("device %s: received %llu, accepted %llu, malformed %llu, wrong version %llu, duplicated %llu, "
                "stale %llu, lost %llu\n",
                o.devices[i].c_str(), static_cast<unsigned long long>(c.received),
                static_cast<unsigned long long>(c.accepted), static_cast<unsigned long long>(c.malformed),
                static_cast<unsigned long long>(c.unsupported_version), static_cast<unsigned long long>(c.duplicated),
                static_cast<unsigned long long>(c.stale), static_cast<unsigned long long>(c.lost));
    std::printf("  safety: clamped %llu, rate-limited %llu, non-finite %llu, watchdog %llu, e-stop %llu ticks; "
                "passivity observer: %.6f J injected\n",
                static_cast<unsigned long long>(s.clamped), static_cast<unsigned long long>(s.rate_limited),
                static_cast<unsigned long long>(s.non_finite), static_cast<unsigned long long>(s.watchdog),
                static_cast<unsigned long long>(s.emergency), report.injected_energy[i]);
  }
  if (recorder)
    std::printf("wrote %s (%llu ticks, %llu dropped)\n", o.record.c_str(),
                static_cast<unsigned long long>(recorder->written()), static_cast<unsigned long long>(recorder->dropped()));
}

void add_servo_options(CLI::App& c, HapticOptions& o) {
  c.add_option("--rate", o.rate, "servo rate [Hz] (100..10000)")->capture_default_str();
  c.add_option("--model-rate", o.model_rate,
               "run the model in its own thread at this rate [Hz] (< rate; the servo interpolates); 0 = in the servo "
               "thread")
      ->capture_default_str();
  c.add_option("--record", o.record, "session file to record every tick to (append-only CSV)");
  c.add_option("--duration", o.duration, "seconds until the ramp out begins; 0 = until Ctrl-C")->capture_default_str();
  c.add_option("--device-model", o.device_model,
               "the device, for its maximum force and stable stiffness: " + device_model_names())
      ->capture_default_str();
  c.add_option("--max-force", o.max_force,
               "force clamp [N], at most the device model's (default: its maximum; the device's declared maximum "
               "applies too)")
      ->capture_default_str();
  c.add_option("--force-rate", o.force_rate, "force-rate limit [N/s]")->capture_default_str();
  c.add_option("--ramp", o.ramp, "ramp in/out time [s]")->capture_default_str();
  c.add_option("--watchdog", o.watchdog,
               "zero force once the newest device state is this old [s] (default 10 ms, at least two servo periods)");
  c.add_option("--coupling-stiffness", o.coupling.stiffness,
               "render through Colgate's virtual coupling of this stiffness [N/m]; 0 = the model's force directly")
      ->capture_default_str();
  c.add_option("--coupling-damping", o.coupling.damping, "virtual coupling damping [N s/m]")->capture_default_str();
  c.add_option("--virtual-mass", o.coupling.virtual_mass, "virtual tool mass of the coupling [kg]")
      ->capture_default_str();
  c.add_flag("--no-realtime", o.no_realtime, "do not ask for SCHED_FIFO and locked memory");
}

void read_given_servo_options(const CLI::App& c, HapticOptions& o) {
  o.max_force_given = c.count("--max-force") > 0;
  o.watchdog_given = c.count("--watchdog") > 0;
}

std::string model_names() {
  std::string names;
  for (const ModelDescription& d : model_catalogue()) names += (names.empty() ? "" : ", ") + std::string(d.name);
  return names;
}

} // namespace kerf::cli
