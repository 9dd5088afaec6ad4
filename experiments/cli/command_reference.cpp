// kerf reference SCENE [--degree 1|2] [--refine K] [--samples N] [-o DIR] [--resume] [--no-fields] [--fracture auto|on|off]:
// the finite-strain reference along the scene's trajectory (issue 3), written as profile.csv +
// manifest.json (+ fields.pvd), with a progress line per sample and checkpoints to resume from.

#include "experiments/cli/commands.hpp"
#include "experiments/run/reference_run.hpp"
#include "experiments/run/session_replay.hpp"
#include "experiments/run/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "experiments/study/study_runner.hpp"
#include "experiments/trajectory/trajectory.hpp"

#include <chrono>
#include <cstdio>
#include <memory>

namespace kerf::cli {

namespace {

struct ReferenceOptions {
  std::string scene;
  std::string out;
  int degree = 1;
  int refine = 0;
  int samples = 0; ///< 0 = every trajectory sample
  bool resume = false;
  std::string fracture = "auto";
  bool no_fields = false;
  std::string trajectory; ///< a haptic session file whose tool positions replace the scene's trajectories
};

void run_reference_command(const ReferenceOptions& o) {
  namespace fs = std::filesystem;
  const Scene read = read_scene(resolve_scene(o.scene));
  const fs::path out = o.out.empty() ? fs::path("runs") / read.name / "reference" : fs::path(o.out);
  // A recorded session replays what the hand did at the rig through the ground truth.
  const Scene scene = o.trajectory.empty() ? read : replay_session(read, o.trajectory, out);
  ReferenceRunSettings settings;
  settings.degree = o.degree;
  settings.refinements = o.refine;
  settings.write_fields = !o.no_fields;
  settings.resume = o.resume;
  settings.fracture = o.fracture == "on" ? ReferenceFracture::on : o.fracture == "off" ? ReferenceFracture::off : ReferenceFracture::automatic;
  if (o.samples < 0) throw std::invalid_argument("--samples must be >= 1, got " + std::to_string(o.samples));
  if (o.samples > 0) {
    if (scene.tools.empty()) throw std::invalid_argument("scene '" + scene.name + "' has no tool");
    settings.sample_indices = reference_sample_indices(sample(scene.tools.front().trajectory).samples.size(), o.samples);
  }
  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene);
  const ForceProfile profile = run_reference(scene, mesh, settings, out);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  double peak = 0.0;
  for (const ProfileRow& r : profile.rows) peak = std::max(peak, r.force.norm());
  std::printf("%s / reference (P%d, %d refinements): %zu samples solved, peak |F| %.6g N, wall %.2f s\n",
              scene.name.c_str(), o.degree, o.refine, profile.rows.size(), peak, wall);
  std::printf("wrote %s, %s%s\n", (out / "profile.csv").c_str(), (out / "manifest.json").c_str(),
              settings.write_fields ? (", " + (out / "fields.pvd").string()).c_str() : "");
}

} // namespace

void add_reference_command(CLI::App& app) {
  auto options = std::make_shared<ReferenceOptions>();
  auto* cmd = app.add_subcommand("reference", "finite-strain reference run on a scene: profile.csv, manifest.json, fields.pvd");
  cmd->add_option("scene", options->scene, "scene file or name")->required();
  cmd->add_option("--degree", options->degree, "finite element degree")->check(CLI::IsMember({1, 2}));
  cmd->add_option("--refine", options->refine, "global mesh refinements")->check(CLI::Range(0, 4));
  cmd->add_option("--samples", options->samples,
                  "solve N evenly spaced trajectory samples, first and last included (default: every sample)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("-o,--output", options->out, "output directory (default runs/SCENE/reference)");
  cmd->add_flag("--resume", options->resume, "continue from DIR/checkpoint.bin");
  cmd->add_flag("--no-fields", options->no_fields, "do not write fields.pvd and the .vtu files");
  cmd->add_option("--fracture", options->fracture,
                  "cohesive fracture along the scene's cut_plane: auto (cutting/tearing scenes with σ_c and J_c), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_option("--trajectory", options->trajectory,
                  "a haptic session file (kerf haptic --record): its tool positions replace the scene's trajectories");
  cmd->callback([options] { run_reference_command(*options); });
}

} // namespace kerf::cli
