#pragma once
// The kerf command line: one file per subcommand, each adding itself to the application. A
// subcommand's callback does the work and throws on failure; main() maps exceptions to exit codes.

#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>

namespace kerf::cli {

void add_mesh_command(CLI::App& app);   ///< kerf mesh SCENE [-o DIR]
void add_run_command(CLI::App& app);    ///< kerf run SCENE --model M [-o DIR]
void add_models_command(CLI::App& app); ///< kerf models
void add_stability_command(CLI::App& app); ///< kerf stability SCENE --model M [-o DIR]
void add_study_command(CLI::App& app);     ///< kerf study STUDY [-o DIR] [--results-doc FILE] [--jobs N] (mpirun-able)
void add_calibrate_command(CLI::App& app); ///< kerf calibrate SCENE --model M [--trajectory S] [--target P] [-o FILE]
void add_recommend_command(CLI::App& app); ///< kerf recommend SCENE --max-error 10% --rate 1000 [--tables DIR]
void add_view_command(CLI::App& app);      ///< kerf view SCENE --model M | RUN_DIR... [--screenshot F --at T]
void add_reference_command(CLI::App& app); ///< kerf reference SCENE [--degree 1|2] [--refine K] [--samples N] [-o DIR] [--resume] [--no-fields]

} // namespace kerf::cli
