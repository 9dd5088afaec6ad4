// kerf-rig replay SESSION [--scene S] [--model M] [--rate HZ] [--record FILE] ...: a recorded
// session's hand motion through the servo loop again, in real time: one replay device per tool of
// the session (`replay:SESSION#N`, realtime/haptics/replay_device.hpp), by default with the
// session's scene, model and rate and for the length of the recording. With another --model,
// --model-rate, coupling or safety limits it shows what the same motion renders under them, on
// the rig's own code path (the servo loop, the safety layer, the recorder).

#include "apps/kerf-rig/haptic_session.hpp"
#include "apps/kerf-rig/rig_commands.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/haptics/session_file.hpp"

#include <memory>

namespace kerf::cli {

void add_replay_command(CLI::App& app) {
  auto o = std::make_shared<HapticOptions>();
  auto session = std::make_shared<std::string>();
  auto* c = app.add_subcommand("replay", "a recorded session's hand motion through the servo loop again, in real time "
                                         "(docs/haptic-rig.md)");
  c->add_option("session", *session, "session file (kerf-rig haptic --record)")->required();
  c->add_option("--scene", o->scene, "scene file or name (default: the session's scene, by name)");
  c->add_option("--model", o->model, "model name (default: the session's): " + model_names());
  add_servo_options(*c, *o);
  c->callback([o, session, c] {
    read_given_servo_options(*c, *o);
    const Session recorded = read_session(*session);
    if (o->scene.empty()) {
      o->scene = recorded.header.scene;
      try {
        resolve_scene(o->scene);
      } catch (const SceneError& e) {
        throw SceneError(std::string(e.what()) + " (the scene named in " + *session + "; give --scene FILE)");
      }
    }
    if (o->model.empty()) o->model = recorded.header.model;
    if (c->count("--rate") == 0) o->rate = recorded.header.rate;
    if (c->count("--duration") == 0 && !recorded.ticks.empty()) o->duration = recorded.ticks.back().t;
    o->devices.clear();
    for (std::size_t i = 0; i < recorded.header.tools.size(); ++i)
      o->devices.push_back("replay:" + *session + "#" + std::to_string(i));
    run_haptic(*o);
  });
}

} // namespace kerf::cli
