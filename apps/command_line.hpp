#pragma once
// How kerf's programs (kerf, kerf-rig) end: the command line parsed, the chosen subcommand run,
// and what it throws mapped to an exit status and one line on stderr:
//   0 done; 1 any other error; 2 a scene or mesh error (the file and place named); 3 a model that
//   cannot represent the scene (what is missing named); 4 a reference whose load path stopped before
//   the trajectory's end (kerf reference, or a reference a study solved or read): what it solved is
//   written, its manifest marked `partial`, and the message names the sample it stopped at;
//   CLI11's own statuses for a bad command line.

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/mesh_error.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

namespace kerf::cli {

/// Exit status 4 (see file comment): a reference's load path stopped; its partial results are written.
inline constexpr int exit_reference_stopped = 4;

/// A command that ran to its end and wrote what it could, whose result is nevertheless incomplete:
/// the program ends with `status` and the message.
class IncompleteRun : public std::runtime_error {
public:
  IncompleteRun(int status, const std::string& what) : std::runtime_error(what), m_status(status) {}
  [[nodiscard]] int status() const { return m_status; }

private:
  int m_status;
};

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
  } catch (const IncompleteRun& e) {
    std::fprintf(stderr, "%s: incomplete: %s\n", program, e.what());
    return e.status();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return 1;
  }
  return 0;
}

} // namespace kerf::cli
