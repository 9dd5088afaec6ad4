// kerf — the research command line: meshes, model runs, the finite-element reference, studies,
// calibration, stability sweeps, recommendations, the viewer. Each subcommand lives in its own
// file (commands.hpp). The live rig is its own program, kerf-rig (apps/kerf-rig).

#include "apps/command_line.hpp"
#include "apps/kerf/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"kerf — haptic cutting and deformation: fast models, a finite-element reference, and the studies "
               "that score one against the other (the live rig: kerf-rig)"};
  app.set_version_flag("--version", std::string("kerf ") + KERF_VERSION + " (" + KERF_GIT_COMMIT + ")");
  app.require_subcommand(1);
  kerf::cli::add_mesh_command(app);
  kerf::cli::add_run_command(app);
  kerf::cli::add_models_command(app);
  kerf::cli::add_stability_command(app);
  kerf::cli::add_study_command(app);
  kerf::cli::add_calibrate_command(app);
  kerf::cli::add_recommend_command(app);
  kerf::cli::add_reference_command(app);
  kerf::cli::add_view_command(app);
  return kerf::cli::run_command_line(app, argc, argv, "kerf");
}
