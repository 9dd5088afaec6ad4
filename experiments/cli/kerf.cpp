// kerf — the command line: mesh a scene, run a model on it, list the models.

#include "experiments/run/model_catalogue.hpp"
#include "experiments/run/run_model.hpp"
#include "experiments/run/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "meshes/gmsh_io.hpp"
#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"
#include "meshes/vtu_writer.hpp"
#include "realtime/fracture/contact_length.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>

namespace fs = std::filesystem;
using namespace kerf;

namespace {

/// A scene argument is a path to a .toml file, or the name of a scene in experiments/scenes.
fs::path resolve_scene(const std::string& argument) {
  fs::path p(argument);
  if (fs::exists(p)) return p;
  if (p.extension().empty()) {
    const fs::path named = fs::path(KERF_SCENES_DIR) / (argument + ".toml");
    if (fs::exists(named)) return named;
  }
  throw SceneError(argument + ": no such scene file, and no scene of that name in " + std::string(KERF_SCENES_DIR));
}

int command_mesh(const std::string& scene_argument, fs::path out) {
  const Scene scene = read_scene(resolve_scene(scene_argument));
  if (out.empty()) out = fs::path("runs") / scene.name / "mesh";
  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  write_msh(mesh, out / "mesh.msh");
  write_vtu(mesh, out / "mesh.vtu");

  const TetQualitySummary q = tet_quality_summary(mesh);
  std::printf("%s: %d nodes, %d tetrahedra, meshed in %.2f s (element size %.3g mm)\n", scene.name.c_str(),
              q.node_count, q.tet_count, seconds, scene.geometry.element_size * 1e3);
  std::printf("  volume %.9g mm^3\n", q.total_volume * 1e9);
  std::printf("  inverted %d, degenerate %d, slivers %d\n", q.inverted, q.degenerate, q.slivers);
  std::printf("  min dihedral angle %.2f deg, radius ratio min %.3f mean %.3f\n",
              q.min_dihedral_angle * 180.0 / std::numbers::pi, q.min_radius_ratio, q.mean_radius_ratio);
  std::printf("  physical volumes:");
  for (const VolumeGroup& g : mesh.volume_groups) std::printf(" %s(%zu)", g.name.c_str(), g.tets.size());
  std::printf("\n  physical surfaces:");
  for (const SurfaceGroup& g : mesh.surface_groups) std::printf(" %s(%ld)", g.name.c_str(), static_cast<long>(g.triangles.rows()));
  std::printf("\nwrote %s, %s\n", (out / "mesh.msh").c_str(), (out / "mesh.vtu").c_str());
  return 0;
}

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

int command_run(const std::string& scene_argument, const std::string& model_name, fs::path out) {
  const Scene scene = read_scene(resolve_scene(scene_argument));
  require_model_for_scene(model_name, scene); // refuse before any meshing
  if (out.empty()) out = fs::path("runs") / scene.name / model_name;

  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model(model_name, scene, mesh);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(scene));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const nlohmann::json manifest = run_manifest(scene, built, mesh, profile, wall);
  write_run(out, profile, manifest);

  std::string sequence;
  InteractionMode last{};
  bool first = true;
  for (const ProfileRow& r : profile.rows) {
    if (!first && r.mode == last) continue;
    sequence += (first ? "" : " -> ") + std::string(to_string(r.mode));
    last = r.mode;
    first = false;
  }
  const CostStatistics cost = cost_statistics(profile);
  std::printf("%s / %s: %zu samples; modes %s\n", scene.name.c_str(), model_name.c_str(), cost.steps, sequence.c_str());
  print_cutting_check(scene, mesh, profile);
  std::printf("cost per step: median %.2f us, p99 %.2f us, max %.2f us (p99 allows %.0f Hz)\n", cost.median * 1e6,
              cost.p99 * 1e6, cost.max * 1e6, cost.rate_allowed());
  std::printf("wrote %s, %s\n", (out / "profile.csv").c_str(), (out / "manifest.json").c_str());
  return 0;
}

int command_models() {
  for (const ModelDescription& m : model_catalogue()) {
    std::printf("%-10s %s\n", std::string(m.name).c_str(), std::string(m.summary).c_str());
    std::printf("%-10s covers: %s; tools: %s; source: %s\n", "", m.covers.to_string().c_str(),
                std::string(m.tools).c_str(), std::string(m.source).c_str());
  }
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"kerf — haptic cutting and deformation: fast models, a finite-element reference, and the studies "
               "that score one against the other"};
  app.set_version_flag("--version", std::string("kerf ") + KERF_VERSION + " (" + KERF_GIT_COMMIT + ")");
  app.require_subcommand(1);

  std::string scene_argument, model_name;
  std::string out;
  auto* mesh = app.add_subcommand("mesh", "mesh a scene's geometry: mesh.msh, mesh.vtu and a quality summary");
  mesh->add_option("scene", scene_argument, "scene file or name (experiments/scenes/NAME.toml)")->required();
  mesh->add_option("-o,--output", out, "output directory (default runs/SCENE/mesh)");

  auto* run = app.add_subcommand("run", "run a model on a scene: profile.csv and manifest.json");
  run->add_option("scene", scene_argument, "scene file or name")->required();
  run->add_option("--model", model_name, "model name (see `kerf models`)")->required();
  run->add_option("-o,--output", out, "output directory (default runs/SCENE/MODEL)");

  auto* models = app.add_subcommand("models", "list the models and the phenomena each covers");

  CLI11_PARSE(app, argc, argv);
  try {
    if (mesh->parsed()) return command_mesh(scene_argument, out);
    if (run->parsed()) return command_run(scene_argument, model_name, out);
    if (models->parsed()) return command_models();
  } catch (const SceneError& e) {
    std::fprintf(stderr, "kerf: scene error: %s\n", e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "kerf: mesh error: %s\n", e.what());
    return 2;
  } catch (const ModelMismatch& e) {
    std::fprintf(stderr, "kerf: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kerf: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
