// kerf run SCENE --model M [-o DIR]: a model stepped along the scene's trajectories, written as
// profile.csv + manifest.json, with a short report (mode sequence, paper 001's J_c l check, cost).

#include "apps/kerf/commands.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/records/run_record.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "experiments/models/session_replay.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/fracture/contact_length.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

namespace kerf::cli {

namespace {

struct RunOptions {
  std::string scene;
  std::string model;
  std::string out;
  std::string integrator; ///< forwarded to the model as option "integrator"
  std::string trajectory; ///< a haptic session file whose tool positions replace the scene's trajectories
};

/// The paper 001 check printed after a cutting run: the steady cutting force beside J_c l
/// (Eq. 10), l measured on the mesh at the median cutting sample.
void print_cutting_check(const Scene& scene, const TetMesh& mesh, const ForceProfile& profile) {
  if (scene.tools.size() != 1 || scene.tools.front().kind != Tool::Kind::blade) return;
  std::vector<const ProfileRow*> cutting;
  for (const ProfileRow& r : profile.rows)
    if (r.mode == InteractionMode::cutting) cutting.push_back(&r);
  if (cutting.empty()) return;
  const BladeShape& blade = scene.tools.front().blade;
  const ProfileRow& mid = *cutting[cutting.size() / 2];
  const double force = -mid.force.dot(blade.cutting_direction);

  const auto [regions, toughness] = toughness_regions(scene);
  SegmentLengthInBody length(mesh, regions);
  std::vector<double> l(toughness.size());
  const Eigen::Vector3d half = 0.5 * blade.edge_length * blade.edge_direction;
  length.lengths(mid.position - half, mid.position + half, l);
  double jl = 0.0;
  std::string terms;
  for (std::size_t k = 0; k < l.size(); ++k) {
    jl += toughness[k] * l[k];
    char term[96];
    std::snprintf(term, sizeof term, "%s%.0f J/m^2 x %.3f mm", k ? " + " : "", toughness[k], l[k] * 1e3);
    terms += term;
  }
  std::printf("steady cutting force %.4f N at depth %.3f mm; J_c l = %s = %.4f N (paper 001 Eq. 10)\n", force,
              mid.crack_extent * 1e3, terms.c_str(), jl);
}

void run_run(const RunOptions& o) {
  namespace fs = std::filesystem;
  const Scene scene = read_scene(resolve_scene(o.scene));
  require_model_for_scene(o.model, scene); // refuse before any meshing
  const fs::path out = o.out.empty() ? fs::path("runs") / scene.name / o.model : fs::path(o.out);

  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene);
  ModelOptions options;
  if (!o.integrator.empty()) options["integrator"] = o.integrator;
  BuiltModel built = make_model(o.model, scene, mesh, options);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const ForceProfile profile = run_model(
      *built.model, names, o.trajectory.empty() ? sample_scene_trajectories(scene) : session_trajectories(o.trajectory, names));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  write_run(out, profile, run_manifest(scene, built, mesh, profile, wall), &built);

  std::string sequence;
  for (std::size_t k = 0; k < profile.rows.size(); ++k)
    if (k == 0 || profile.rows[k].mode != profile.rows[k - 1].mode)
      sequence += (k == 0 ? "" : " -> ") + std::string(to_string(profile.rows[k].mode));
  const CostStatistics cost = cost_statistics(profile);
  std::printf("%s / %s: %zu samples; modes %s\n", scene.name.c_str(), o.model.c_str(), cost.steps, sequence.c_str());
  print_cutting_check(scene, mesh, profile);
  std::printf("cost per step: median %.2f us, p99 %.2f us, max %.2f us (p99 allows %.0f Hz)\n", cost.median * 1e6,
              cost.p99 * 1e6, cost.max * 1e6, cost.rate_allowed());
  std::printf("wrote %s, %s\n", (out / "profile.csv").c_str(), (out / "manifest.json").c_str());
}

} // namespace

void add_run_command(CLI::App& app) {
  auto options = std::make_shared<RunOptions>();
  auto* run = app.add_subcommand("run", "run a model on a scene: profile.csv and manifest.json");
  run->add_option("scene", options->scene, "scene file or name")->required();
  run->add_option("--model", options->model, "model name (see `kerf models`)")->required();
  run->add_option("-o,--output", options->out, "output directory (default runs/SCENE/MODEL)");
  run->add_option("--integrator", options->integrator, "time integrator of models that take one (springs: explicit|explicit-double|implicit|linear-implicit|static)");
  run->add_option("--trajectory", options->trajectory, "a haptic session file (kerf-rig haptic --record): its tool positions replace the scene's trajectories");
  run->callback([options] { run_run(*options); });
}

} // namespace kerf::cli
