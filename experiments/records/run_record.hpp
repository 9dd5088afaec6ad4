#pragma once
// What a run of a model leaves on disk: DIR/profile.csv, DIR/manifest.json (the scene's file and
// SHA-256, the model and its parameters, kerf's version and commit, the mesh, the totals) and the
// model's own outputs (the .vtu files of BuiltModel::write_outputs, written through VTK).

#include "experiments/models/model_catalogue.hpp"
#include "formats/profile/force_profile.hpp"
#include "formats/scene/scene.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace kerf {

/// The manifest of a run: scene (name, file, SHA-256), model and its parameters, kerf version
/// and git commit, mesh size, and totals (samples, cost statistics, samples per mode, work done
/// by each tool, final crack extent).
nlohmann::json run_manifest(const Scene& scene, const BuiltModel& model, const TetMesh& mesh,
                            const ForceProfile& profile, double wall_seconds);

/// What `kerf run` writes: DIR/profile.csv and DIR/manifest.json, each atomically; with `model`,
/// also the model's own outputs (BuiltModel::write_outputs), whose entries join the manifest.
void write_run(const std::filesystem::path& dir, const ForceProfile& profile, const nlohmann::json& manifest,
               const BuiltModel* model = nullptr);

} // namespace kerf
