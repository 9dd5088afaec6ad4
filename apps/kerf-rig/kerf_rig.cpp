// kerf-rig — the live haptic rig: a fast model in the servo loop driving haptic devices
// (`haptic`), emulated devices over kerf's device protocol (`device-sim`), and a recorded session
// through the servo loop again (`replay`). It links the realtime models, meshes, the scene reader
// and the model builders only: no deal.II, PETSc, VTK, MPI or OpenSSL (docs/haptic-rig.md).

#include "apps/command_line.hpp"
#include "apps/kerf-rig/rig_commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"kerf-rig — the live haptic rig: a fast model in a servo loop at 1 kHz, emulated devices, replay of "
               "recorded sessions"};
  app.set_version_flag("--version", std::string("kerf-rig ") + KERF_VERSION + " (" + KERF_GIT_COMMIT + ")");
  app.require_subcommand(1);
  kerf::cli::add_haptic_command(app);
  kerf::cli::add_device_sim_command(app);
  kerf::cli::add_replay_command(app);
  return kerf::cli::run_command_line(app, argc, argv, "kerf-rig");
}
