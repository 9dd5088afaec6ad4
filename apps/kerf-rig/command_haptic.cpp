// kerf-rig haptic SCENE --model M --device ADDRESS [--device ADDRESS] [--rate HZ] [--record FILE] ...:
// the live rig, one device per tool of the scene, in scene order (haptic_session.hpp).

#include "apps/kerf-rig/haptic_session.hpp"
#include "apps/kerf-rig/rig_commands.hpp"

#include <memory>

namespace kerf::cli {

void add_haptic_command(CLI::App& app) {
  auto o = std::make_shared<HapticOptions>();
  auto* c = app.add_subcommand("haptic", "drive haptic device(s) with a model: the live rig (docs/haptic-rig.md)");
  c->add_option("scene", o->scene, "scene file or name")->required();
  c->add_option("--model", o->model, "model name: " + model_names())->required();
  c->add_option("--device", o->devices, "udp://HOST:PORT or replay:FILE, one per tool in scene order")->required();
  add_servo_options(*c, *o);
  c->callback([o, c] {
    read_given_servo_options(*c, *o);
    run_haptic(*o);
  });
}

} // namespace kerf::cli
