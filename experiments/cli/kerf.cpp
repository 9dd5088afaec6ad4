// kerf — the command line. Each subcommand lives in its own file (commands.hpp).

#include "experiments/cli/commands.hpp"
#include "experiments/run/model_catalogue.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "meshes/mesh_error.hpp"

#include <cstdio>

int main(int argc, char** argv) {
  CLI::App app{"kerf — haptic cutting and deformation: fast models, a finite-element reference, and the studies "
               "that score one against the other"};
  app.set_version_flag("--version", std::string("kerf ") + KERF_VERSION + " (" + KERF_GIT_COMMIT + ")");
  app.require_subcommand(1);
  kerf::cli::add_mesh_command(app);
  kerf::cli::add_run_command(app);
  kerf::cli::add_models_command(app);
  kerf::cli::add_haptic_command(app);
  kerf::cli::add_device_sim_command(app);
  kerf::cli::add_stability_command(app);
  kerf::cli::add_study_command(app);
  kerf::cli::add_calibrate_command(app);
  kerf::cli::add_recommend_command(app);
  kerf::cli::add_reference_command(app);
  kerf::cli::add_view_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const kerf::SceneError& e) {
    std::fprintf(stderr, "kerf: scene error: %s\n", e.what());
    return 2;
  } catch (const kerf::MeshError& e) {
    std::fprintf(stderr, "kerf: mesh error: %s\n", e.what());
    return 2;
  } catch (const kerf::ModelMismatch& e) {
    std::fprintf(stderr, "kerf: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kerf: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
