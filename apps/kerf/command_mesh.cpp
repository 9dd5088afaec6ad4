// kerf mesh SCENE [--reference] [--element-size H] [-o DIR]: the scene's body as tetrahedra, mesh.msh +
// mesh.vtu + a quality summary; with --reference, the mesh the finite-element reference solves on
// (graded where the physics needs it: scene_mesh.hpp) and the parameters kerf derived for it.

#include "apps/kerf/commands.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/quantity.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/gmsh_io.hpp"
#include "meshes/tet_quality.hpp"
#include "meshes/vtu_writer.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <numbers>

namespace kerf::cli {

namespace {

struct MeshOptions {
  std::string scene;
  std::string out;
  bool reference = false;
  std::string element_size; ///< overrides the scene's element size ("5 mm"); empty = the scene's
};

void run_mesh(const MeshOptions& o) {
  namespace fs = std::filesystem;
  Scene scene = read_scene(resolve_scene(o.scene));
  if (!o.element_size.empty()) scene.geometry.element_size = parse_quantity(o.element_size, Dimension::length);
  const fs::path out = o.out.empty() ? fs::path("runs") / scene.name / (o.reference ? "reference_mesh" : "mesh") : fs::path(o.out);
  const MeshPurpose purpose = o.reference ? MeshPurpose::reference : MeshPurpose::scene;
  const auto begin = std::chrono::steady_clock::now();
  const TetMesh mesh = scene_mesh(scene, purpose);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  write_msh(mesh, out / "mesh.msh");
  write_vtu(mesh, out / "mesh.vtu");

  const TetQualitySummary q = tet_quality_summary(mesh);
  std::printf("%s: %d nodes, %d tetrahedra, meshed in %.2f s (element size %.3g mm)\n", scene.name.c_str(),
              q.node_count, q.tet_count, seconds, scene.geometry.element_size * 1e3);
  const auto derived = scene_mesh_parameters(scene, purpose);
  if (!derived.empty()) {
    std::printf("  derived from the scene:");
    for (const auto& [name, value] : derived) std::printf(" %s = %.4g mm", name.c_str(), value * 1e3);
    std::printf("\n");
  }
  std::printf("  volume %.9g mm^3\n", q.total_volume * 1e9);
  std::printf("  inverted %d, degenerate %d, slivers %d\n", q.inverted, q.degenerate, q.slivers);
  std::printf("  min dihedral angle %.2f deg, radius ratio min %.3f mean %.3f\n",
              q.min_dihedral_angle * 180.0 / std::numbers::pi, q.min_radius_ratio, q.mean_radius_ratio);
  std::printf("  physical volumes:");
  for (const VolumeGroup& g : mesh.volume_groups) std::printf(" %s(%zu)", g.name.c_str(), g.tets.size());
  std::printf("\n  physical surfaces:");
  for (const SurfaceGroup& g : mesh.surface_groups)
    std::printf(" %s(%ld)", g.name.c_str(), static_cast<long>(g.triangles.rows()));
  std::printf("\nwrote %s, %s\n", (out / "mesh.msh").c_str(), (out / "mesh.vtu").c_str());
}

} // namespace

void add_mesh_command(CLI::App& app) {
  auto options = std::make_shared<MeshOptions>();
  auto* mesh = app.add_subcommand("mesh", "mesh a scene's geometry: mesh.msh, mesh.vtu and a quality summary");
  mesh->add_option("scene", options->scene, "scene file or name (experiments/scenes/NAME.toml)")->required();
  mesh->add_option("-o,--output", options->out, "output directory (default runs/SCENE/mesh, runs/SCENE/reference_mesh)");
  mesh->add_flag("--reference", options->reference,
                 "the finite-element reference's mesh: graded at grasp rims and on the crack path (docs/reference.md)");
  mesh->add_option("--element-size", options->element_size,
                   "mesh at this element size instead of the scene's (a length, e.g. \"5 mm\"); graded sizes scale with it");
  mesh->callback([options] { run_mesh(*options); });
}

} // namespace kerf::cli
