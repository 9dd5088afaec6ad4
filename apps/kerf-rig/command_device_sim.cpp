// kerf-rig device-sim SCENE [--port P]... [--record FILE]: emulated haptic device(s) speaking kerf's
// device protocol (docs/device-protocol.md) over UDP, one per tool of the scene, each a simulated
// hand (mass–spring–damper arm) following that tool's trajectory in the scene, under the forces
// the rig commands. Records every force command it accepted. Runs until the trajectory (plus
// hold and tail) is done after the rig's first command, or SIGINT/SIGTERM.

#include "apps/kerf-rig/rig_commands.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/atomic_file.hpp"
#include "realtime/haptics/device_emulator.hpp"
#include "realtime/haptics/device_specs.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <thread>

namespace kerf::cli {

namespace {

struct DeviceSimOptions {
  std::string scene;
  std::vector<int> ports;
  std::string host = "127.0.0.1";
  double rate = 1000.0;
  std::string device_model{default_device_model};
  double max_force = 0.0; ///< [N] 0: the device model's maximum force
  HandParameters hand;
  double hold = 0.5;
  double tail = 0.5;
  double estop_after = -1.0;
  std::string record;
};

std::atomic<bool> stop_requested{false};
extern "C" void stop_signal(int) { stop_requested.store(true); }

void write_received(const std::filesystem::path& file, const std::vector<std::string>& tools,
                    const std::vector<std::unique_ptr<DeviceEmulator>>& emulators) {
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    std::FILE* f = std::fopen(temporary.c_str(), "w");
    if (!f) throw std::runtime_error(temporary.string() + ": cannot write");
    std::fprintf(f, "t,tool,sequence,status,fx,fy,fz,hand_x,hand_y,hand_z\n");
    for (std::size_t i = 0; i < emulators.size(); ++i)
      for (const ReceivedForce& r : emulators[i]->received())
        std::fprintf(f, "%.9f,%s,%u,%u,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", r.time, tools[i].c_str(), r.sequence,
                     r.status, r.force.x(), r.force.y(), r.force.z(), r.hand.x(), r.hand.y(), r.hand.z());
    if (std::fclose(f) != 0) throw std::runtime_error(temporary.string() + ": write failed");
  });
}

void run_device_sim(const DeviceSimOptions& o) {
  const Scene scene = read_scene(resolve_scene(o.scene));
  std::vector<int> ports = o.ports;
  if (ports.empty())
    for (std::size_t i = 0; i < scene.tools.size(); ++i) ports.push_back(47000 + static_cast<int>(i));
  if (ports.size() != scene.tools.size())
    throw std::invalid_argument("device-sim: scene " + scene.name + " has " + std::to_string(scene.tools.size()) +
                                " tool(s); give one --port per tool (got " + std::to_string(ports.size()) + ")");
  const std::vector<SampledTrajectory> targets = sample_scene_trajectories(scene);
  const double max_force = o.max_force > 0.0 ? o.max_force : device_specs(o.device_model).max_force;

  std::vector<std::unique_ptr<DeviceEmulator>> emulators;
  std::vector<std::string> tools;
  for (std::size_t i = 0; i < ports.size(); ++i) {
    EmulatedDeviceSettings s;
    s.host = o.host;
    s.port = ports[i];
    s.rate = o.rate;
    s.max_force = max_force;
    s.hand = o.hand;
    s.hold = o.hold;
    s.tail = o.tail;
    s.emergency_stop_at = o.estop_after;
    for (const ToolState& t : targets[i].samples) s.target.push_back(t.position);
    s.target_rate = targets[i].rate;
    emulators.push_back(std::make_unique<DeviceEmulator>(s));
    tools.push_back(scene.tools[i].name);
    std::printf("device %s: udp://%s:%d, %.0f Hz, max %.2f N, hand m = %.3f kg, k = %.0f N/m, zeta = %.2f; "
                "trajectory %.3f s\n",
                tools[i].c_str(), o.host.c_str(), emulators.back()->port(), o.rate, max_force, o.hand.mass,
                o.hand.stiffness, o.hand.damping_ratio, targets[i].duration());
  }
  std::fflush(stdout);

  struct sigaction action {};
  action.sa_handler = stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::vector<std::thread> threads;
  for (auto& e : emulators) threads.emplace_back([&e] { e->run(stop_requested); });
  for (auto& t : threads) t.join();

  for (std::size_t i = 0; i < emulators.size(); ++i) {
    const LinkCounters& c = emulators[i]->counters();
    std::printf("device %s: %zu force commands accepted; received %llu, malformed %llu, wrong version %llu, "
                "duplicated %llu, stale %llu, lost %llu\n",
                tools[i].c_str(), emulators[i]->received().size(), static_cast<unsigned long long>(c.received),
                static_cast<unsigned long long>(c.malformed), static_cast<unsigned long long>(c.unsupported_version),
                static_cast<unsigned long long>(c.duplicated), static_cast<unsigned long long>(c.stale),
                static_cast<unsigned long long>(c.lost));
  }
  if (!o.record.empty()) {
    write_received(o.record, tools, emulators);
    std::printf("wrote %s\n", o.record.c_str());
  }
}

} // namespace

void add_device_sim_command(CLI::App& app) {
  auto o = std::make_shared<DeviceSimOptions>();
  auto* c = app.add_subcommand("device-sim", "emulate haptic device(s) with a simulated hand over kerf's UDP protocol");
  c->add_option("scene", o->scene, "scene file or name: the hand follows each tool's trajectory")->required();
  c->add_option("--port", o->ports, "UDP port per tool, in scene order (default 47000, 47001)");
  c->add_option("--host", o->host, "numeric IPv4 address to listen on")->capture_default_str();
  c->add_option("--rate", o->rate, "device rate [Hz]")->capture_default_str();
  c->add_option("--device-model", o->device_model,
                "the emulated device, for the maximum force it declares: " + device_model_names())
      ->capture_default_str();
  c->add_option("--max-force", o->max_force, "declared maximum force [N] (default: the device model's)");
  c->add_option("--hand-mass", o->hand.mass, "hand + handle mass [kg]")->capture_default_str();
  c->add_option("--hand-stiffness", o->hand.stiffness, "arm stiffness toward the target [N/m]")->capture_default_str();
  c->add_option("--hand-damping-ratio", o->hand.damping_ratio, "arm damping ratio")->capture_default_str();
  c->add_option("--hold", o->hold, "seconds at the start after the rig connects")->capture_default_str();
  c->add_option("--tail", o->tail, "seconds at the end before stopping")->capture_default_str();
  c->add_option("--estop-after", o->estop_after, "press the e-stop button this many seconds after the rig connects");
  c->add_option("--record", o->record, "CSV of every force command received (written atomically at the end)");
  c->callback([o] { run_device_sim(*o); });
}

} // namespace kerf::cli
