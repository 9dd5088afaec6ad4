#pragma once
// How kerf's programs (kerf, kerf-rig) end: the command line parsed, the chosen subcommand run,
// and what it throws mapped to an exit status and one line on stderr:
//   0 done; 1 any other error; 2 a scene or mesh error (the file and place named); 3 a model that
//   cannot represent the scene (what is missing named); CLI11's own statuses for a bad command line.

#include "experiments/models/model_catalogue.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "meshes/mesh_error.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

namespace kerf::cli {

inline int run_command_line(CLI::App& app, int argc, char** argv, const char* program) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s: scene error: %s\n", program, e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "%s: mesh error: %s\n", program, e.what());
    return 2;
  } catch (const ModelMismatch& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return 1;
  }
  return 0;
}

} // namespace kerf::cli
